// Safe output files: inputs never overwritten, existing results only when asked, temporary names
// renamed on success (output_files.hpp).
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/xdmf.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/syscall.h>
#endif

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

namespace frictherm::coupling {

namespace {

bool exists(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0;
}

/// rename(2) that fails with EEXIST instead of replacing: renameat2(RENAME_NOREPLACE) where the kernel
/// and file system have it, else link(2) + unlink(2) (link never replaces either).
int rename_no_replace(const char* from, const char* to) {
#if defined(__linux__) && defined(SYS_renameat2)
  constexpr unsigned kNoReplace = 1u;  // RENAME_NOREPLACE
  if (::syscall(SYS_renameat2, AT_FDCWD, from, AT_FDCWD, to, kNoReplace) == 0) return 0;
  if (errno != EINVAL && errno != ENOSYS) return -1;
#endif
  if (::link(from, to) != 0) return -1;
  ::unlink(from);
  return 0;
}

/// What a non-regular, non-folder file is, for the refusal above.
std::string special_file_kind(mode_t mode) {
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a named pipe";
  if (S_ISSOCK(mode)) return "a socket";
  return "a special file";
}

}  // namespace

std::vector<std::string> scene_input_files(const Scene& scene) {
  std::vector<std::string> files;
  if (!scene.source.empty() && scene.source != "<string>") files.push_back(scene.source);
  for (const BodySpec& b : scene.bodies)
    if (!b.shape.image_file.empty()) files.push_back(b.shape.image_file);
  return files;
}

bool same_file(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  if (::stat(a.c_str(), &sa) != 0 || ::stat(b.c_str(), &sb) != 0) return false;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

void check_output_path(const std::string& path, const std::vector<std::string>& inputs, bool overwrite,
                       const std::string& how_to_overwrite) {
  for (const std::string& in : inputs)
    if (same_file(path, in))
      throw OutputError("refusing to write '" + path + "': it is an input of this run ('" + in +
                        "'); choose another output file");
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;  // nothing there (or a dangling link: created through it)
  if (S_ISDIR(st.st_mode)) throw OutputError("cannot write '" + path + "': it is a folder");
  // A result is published by renaming its temporary file over the name, which would replace a device,
  // pipe or socket (/dev/null, /dev/full) by a regular file: refused, whatever --force says.
  if (!S_ISREG(st.st_mode))
    throw OutputError("cannot write '" + path + "': it is " + special_file_kind(st.st_mode) +
                      ", not a regular file; choose a file name for the result");
  if (!overwrite)
    throw OutputError("'" + path + "' exists; refusing to replace an existing result (give " + how_to_overwrite +
                      " to replace it, or choose another output file)");
}

void check_companion_path(const std::string& path, const std::vector<std::string>& inputs, bool overwrite,
                          const std::string& how_to_overwrite) {
  bool xdmf_text = false;
  if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
    char head[256] = {};
    const std::size_t n = std::fread(head, 1, sizeof head - 1, f);
    std::fclose(f);
    const std::string start(head, n);
    xdmf_text = start.rfind("<?xml", 0) == 0 && start.find("<Xdmf") != std::string::npos;
  }
  check_output_path(path, inputs, overwrite || xdmf_text, how_to_overwrite);
}

void check_output_folder(const std::string& path, const std::string& what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw OutputError(what + ": '" + path + "' is a folder; expected a file name for the result, e.g. '" +
                      (path.empty() || path.back() == '/' ? path : path + "/") + "run.h5'");
  const std::size_t slash = path.find_last_of('/');
  const std::string folder = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  if (::stat(folder.c_str(), &st) != 0)
    throw OutputError(what + ": the folder '" + folder + "' of '" + path + "' does not exist (" +
                      std::strerror(errno) + "); create it first");
  if (!S_ISDIR(st.st_mode)) throw OutputError(what + ": '" + folder + "' in '" + path + "' is not a folder");
}

std::string temporary_path(const std::string& path) {
  const std::string stem = path + "." + std::to_string(static_cast<long>(::getpid()));
  std::string candidate = stem + ".part";
  for (int k = 1; exists(candidate); ++k) candidate = stem + "-" + std::to_string(k) + ".part";
  return candidate;
}

void publish_file(const std::string& temporary, const std::string& path, bool overwrite) {
  const int rc = overwrite ? std::rename(temporary.c_str(), path.c_str())
                           : rename_no_replace(temporary.c_str(), path.c_str());
  if (rc == 0) return;
  const int err = errno;
  if (err == EEXIST)
    throw std::runtime_error("'" + path + "' was created by someone else while this run wrote its result; left it " +
                             "alone: this run's result is in '" + temporary + "'");
  throw std::runtime_error("cannot rename '" + temporary + "' to '" + path + "': " + std::strerror(err) +
                           "; this run's result is in '" + temporary + "'");
}

void publish_with_xdmf(const std::string& temporary, const std::string& path, bool overwrite, const std::string& xdmf,
                       const std::string& reference_xdmf, const std::string& nodes_xdmf) {
  // RUN.xdmf, RUN_reference.xdmf and RUN_nodes.xdmf: each written beside its name first, the old ones
  // removed, the result renamed into place, then the XDMF files (a kill leaves an XDMF that matches
  // its result, or none).
  const std::string pid = "." + std::to_string(static_cast<long>(::getpid())) + ".tmp";
  const std::pair<std::string, const std::string*> files[] = {
      {xdmf_path_for(path), &xdmf}, {xdmf_reference_path_for(path), &reference_xdmf}, {xdmf_nodes_path_for(path), &nodes_xdmf}};
  auto remove_temporaries = [&] {
    for (const auto& f : files) ::unlink((f.first + pid).c_str());
  };
  try {
    for (const auto& f : files)
      if (!f.second->empty()) write_text_atomically(f.first + pid, *f.second);
    if (overwrite)
      for (const auto& f : files) ::unlink(f.first.c_str());
    publish_file(temporary, path, overwrite);
  } catch (...) {
    remove_temporaries();
    throw;
  }
  for (const auto& f : files)
    if (!f.second->empty() && std::rename((f.first + pid).c_str(), f.first.c_str()) != 0) {
      const std::string reason = std::strerror(errno);
      remove_temporaries();
      throw std::runtime_error("'" + path + "' is published but its XDMF file could not be: " + reason);
    }
}

OutputClaim::OutputClaim(const std::string& output) : lock_path_(output + ".lock") {
  // The holder unlinks the lock file before it lets go, so a run that opened the old file and then
  // got its lock holds a file no longer under the name: it tries again on the name's current file.
  for (int attempt = 0; attempt < 100; ++attempt) {
    fd_ = ::open(lock_path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) return;  // a folder we cannot write into: the output's own checks say so
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      ::close(fd_);
      fd_ = -1;
      if (err == EWOULDBLOCK)
        throw OutputError("'" + output + "' is being written by another run (it holds " + lock_path_ +
                          "); refusing to start a second run on the same output");
      return;  // no locks on this file system: unclaimed, as before
    }
    struct stat held {}, named {};
    if (::fstat(fd_, &held) == 0 && ::stat(lock_path_.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
        held.st_ino == named.st_ino)
      return;
    ::close(fd_);
    fd_ = -1;
  }
}

OutputClaim::~OutputClaim() {
  if (fd_ < 0) return;
  ::unlink(lock_path_.c_str());  // while still held: a run waiting on it takes a fresh file
  ::close(fd_);
}

}  // namespace frictherm::coupling
