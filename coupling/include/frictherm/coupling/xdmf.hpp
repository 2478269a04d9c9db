#pragma once
// XDMF 3 text for particle snapshots stored in HDF5 (read by ParaView's Xdmf3ReaderS).
// One temporal collection; one Uniform grid per snapshot with Polyvertex topology (one vertex
// cell per particle, connectivity 0..n-1 read from the HDF5 file), geometry from the snapshot's
// `position` dataset (XY in 2D, XYZ in 3D) and every other field as a node-centred Attribute.
// Heavy data is referenced by the HDF5 file's name relative to the XDMF file. A run with heat also
// gets RUN_nodes.xdmf: the thermal grid's nodes (/nodes/NNNNNN) as Polyvertex points with their
// temperature, a file of its own because ParaView's Xdmf3ReaderS reads the top-level grids of one
// file as pieces of a single data set (the nodes would be merged with the particles).
#include <cstddef>
#include <string>
#include <vector>

namespace frictherm::coupling {

struct XdmfField {
  std::string name;     // dataset name inside the snapshot group
  int components = 1;   // columns of the (n, components) dataset; 1 for an (n) dataset
  bool integer = false; // an integer rather than float64
  int bytes = 0;         // the integer's width in bytes (4 or 8); 0 means 4 (int32). Floats are 8.
};

struct XdmfGrid {
  std::string name;          // grid name shown by ParaView (e.g. "000012" or "failure")
  std::string h5_group;      // absolute HDF5 group path, e.g. "/snapshots/000012"
  std::string connectivity;  // absolute HDF5 path of the int32 dataset 0..points-1
  long step = 0;
  double time = 0.0;
  std::size_t points = 0;
  std::vector<XdmfField> fields;  // must include the geometry field with `dim` components
  // The field drawn as the points: "position" (current configuration x), or "initial_position" for
  // the reference-configuration file RUN_reference.xdmf (X; ParaView's Warp By Vector on
  // `displacement` then moves the points to x = X + u). Neither geometry field is an Attribute.
  std::string geometry = "position";
};

/// "Scalar" (1), "Vector" (3), "Tensor" (9), "Tensor6" (6), otherwise "Matrix". Only these widths are
/// what VTK's filters take as vectors and tensors (Warp By Vector asserts 3 components), so 2D runs
/// write vectors padded to 3 components and the stress as a 3x3 tensor (docs/output.md).
std::string xdmf_attribute_type(int components);

/// The XML of one grid (indented for the temporal collection). Throws std::invalid_argument when
/// the grid has no position field of `dim` components or no points.
std::string xdmf_grid_xml(const XdmfGrid& grid, const std::string& h5_file_name, int dim);

/// A whole XDMF document around already rendered grids (see xdmf_grid_xml).
std::string xdmf_document(const std::vector<std::string>& grid_xml, const std::string& collection = "particles");


/// Writes `text` to `path` atomically: `path`.tmp is written, then renamed over `path`, so a
/// reader never sees a half-written file. Throws std::runtime_error naming the file.
void write_text_atomically(const std::string& path, const std::string& text);

/// RUN.h5 -> RUN.xdmf (also for .hdf5/.he5; any other name gets .xdmf appended).
std::string xdmf_path_for(const std::string& h5_path);

/// RUN.h5 -> RUN_nodes.xdmf: the thermal grid's nodes of every snapshot (/nodes, runs with heat).
std::string xdmf_nodes_path_for(const std::string& h5_path);

/// RUN.h5 -> RUN_reference.xdmf: the snapshots drawn at the reference positions X (the
/// `initial_position` field), for a displacement warp in ParaView (docs/output.md "In ParaView").
std::string xdmf_reference_path_for(const std::string& h5_path);

/// The XDMF files a result RUN.h5 is published with (publish_with_xdmf): RUN.xdmf, RUN_reference.xdmf
/// and RUN_nodes.xdmf. A run checks each as it checks RUN.h5 (check_output_path): never an input, an
/// existing one replaced only when asked.
std::vector<std::string> xdmf_paths_for(const std::string& h5_path);

/// Escapes &, <, >, " and ' for XML text and attribute values.
std::string xml_escape(const std::string& text);

}  // namespace frictherm::coupling
