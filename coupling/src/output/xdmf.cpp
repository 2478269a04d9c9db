#include <frictherm/coupling/xdmf.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace frictherm::coupling {
namespace {

// Shortest decimal text that reads back to the same double.
std::string exact(double value) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof buf, value);
  return std::string(buf, result.ptr);
}

std::string dims_text(std::size_t n, int components) {
  std::string s = std::to_string(n);
  if (components > 1) s += " " + std::to_string(components);
  return s;
}

// integer_bytes: 0 for float64, otherwise the integer's width (4 or 8: VTK reads Int Precision 8 as
// a 64-bit array, e.g. the particle ids of a decomposed run).
void data_item(std::string& out, const std::string& indent, const std::string& dims, int integer_bytes,
               const std::string& h5_file, const std::string& h5_path) {
  const std::string type = integer_bytes == 0 ? "Float\" Precision=\"8\""
                                              : "Int\" Precision=\"" + std::to_string(integer_bytes) + "\"";
  out += indent + "<DataItem Dimensions=\"" + dims + "\" NumberType=\"" + type + " Format=\"HDF\">" +
         xml_escape(h5_file) + ":" + xml_escape(h5_path) + "</DataItem>\n";
}

}  // namespace

std::string xml_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string xdmf_attribute_type(int components) {
  if (components == 1) return "Scalar";
  if (components == 3) return "Vector";
  if (components == 9) return "Tensor";
  if (components == 6) return "Tensor6";
  return "Matrix";  // any other width: read as a plain multi-component array
}

std::string xdmf_grid_xml(const XdmfGrid& grid, const std::string& h5_file_name, int dim) {
  if (dim != 2 && dim != 3) throw std::invalid_argument("XDMF: dim must be 2 or 3");
  if (grid.points == 0) throw std::invalid_argument("XDMF: grid " + grid.name + " has no points");
  const XdmfField* position = nullptr;
  for (const auto& f : grid.fields) {
    if (f.name == grid.geometry) position = &f;
  }
  if (position == nullptr || position->components != dim || position->integer) {
    throw std::invalid_argument("XDMF: grid " + grid.name + " needs a " + grid.geometry + " field with " +
                                std::to_string(dim) + " float components");
  }
  const std::string n = std::to_string(grid.points);
  const std::string in3 = "      ";
  const std::string in4 = in3 + "  ";
  std::string out;
  out += "    <Grid Name=\"" + xml_escape(grid.name) + "\" GridType=\"Uniform\">\n";
  out += in3 + "<Time Value=\"" + exact(grid.time) + "\"/>\n";
  out += in3 + "<Information Name=\"step\" Value=\"" + std::to_string(grid.step) + "\"/>\n";
  out += in3 + "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" + n +
         "\" NodesPerElement=\"1\">\n";
  data_item(out, in4, n, 4, h5_file_name, grid.connectivity);
  out += in3 + "</Topology>\n";
  out += in3 + "<Geometry GeometryType=\"" + (dim == 2 ? "XY" : "XYZ") + "\">\n";
  data_item(out, in4, dims_text(grid.points, dim), 0, h5_file_name,
            grid.h5_group + "/" + grid.geometry);
  out += in3 + "</Geometry>\n";
  for (const auto& f : grid.fields) {
    if (f.name == "position" || f.name == "initial_position") continue;  // the geometries of the two files
    out += in3 + "<Attribute Name=\"" + xml_escape(f.name) + "\" AttributeType=\"" +
           xdmf_attribute_type(f.components) + "\" Center=\"Node\">\n";
    if (f.integer && f.bytes != 0 && f.bytes != 4 && f.bytes != 8)
      throw std::invalid_argument("XDMF: field " + f.name + " has integers of " + std::to_string(f.bytes) +
                                  " bytes (expected 4 or 8)");
    data_item(out, in4, dims_text(grid.points, f.components), f.integer ? (f.bytes == 0 ? 4 : f.bytes) : 0, h5_file_name,
              grid.h5_group + "/" + f.name);
    out += in3 + "</Attribute>\n";
  }
  out += "    </Grid>\n";
  return out;
}

std::string xdmf_document(const std::vector<std::string>& grid_xml, const std::string& collection) {
  std::string out =
      "<?xml version=\"1.0\" ?>\n"
      "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
      "  <Domain>\n"
      "   <Grid Name=\"" + xml_escape(collection) + "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const auto& g : grid_xml) out += g;
  out +=
      "   </Grid>\n"
      "  </Domain>\n"
      "</Xdmf>\n";
  return out;
}

void write_text_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + "." + std::to_string(static_cast<long>(::getpid())) + ".tmp";  // one per process:
                                                                                                  // two writers never share it
  {  // write(2) itself, for the system's reason when it fails (a full disk: "No space left on device")
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error("cannot write '" + tmp + "': " + std::strerror(errno));
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const std::string reason = n < 0 ? std::strerror(errno) : "nothing written";
        ::close(fd);
        std::remove(tmp.c_str());
        throw std::runtime_error("cannot write '" + tmp + "': " + reason);
      }
      done += static_cast<std::size_t>(n);
    }
    if (::close(fd) != 0) {
      const std::string reason = std::strerror(errno);
      std::remove(tmp.c_str());
      throw std::runtime_error("cannot write '" + tmp + "': " + reason);
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot rename '" + tmp + "' to '" + path + "': " + reason);
  }
}

std::string xdmf_reference_path_for(const std::string& h5_path) {
  const std::string x = xdmf_path_for(h5_path);
  return x.substr(0, x.size() - 5) + "_reference.xdmf";
}

std::string xdmf_nodes_path_for(const std::string& h5_path) {
  const std::string x = xdmf_path_for(h5_path);
  return x.substr(0, x.size() - 5) + "_nodes.xdmf";
}

std::vector<std::string> xdmf_paths_for(const std::string& h5_path) {
  return {xdmf_path_for(h5_path), xdmf_reference_path_for(h5_path), xdmf_nodes_path_for(h5_path)};
}

std::string xdmf_path_for(const std::string& h5_path) {
  for (const char* ext : {".h5", ".hdf5", ".he5"}) {
    const std::size_t len = std::strlen(ext);
    if (h5_path.size() > len && h5_path.compare(h5_path.size() - len, len, ext) == 0) {
      return h5_path.substr(0, h5_path.size() - len) + ".xdmf";
    }
  }
  return h5_path + ".xdmf";
}

}  // namespace frictherm::coupling
