#include "store/study_reader.hpp"

#include <H5Cpp.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "store/bounded_child.hpp"
#include "store/h5.hpp"
#include "store/study_file.hpp"

namespace stepbench {
namespace {

// The HDF5 signature, at 0, 512, 1024, 2048, ... (a user block may come first).
bool has_hdf5_signature(const std::vector<char>& bytes) {
  static constexpr char signature[] = "\x89HDF\r\n\x1a\n";
  for (std::size_t at = 0; at + 8 <= bytes.size(); at = at == 0 ? 512 : 2 * at)
    if (std::memcmp(bytes.data() + at, signature, 8) == 0) return true;
  return false;
}

// The whole file from its bytes: the record, then `read_parts`. Errors are
// std::runtime_error or H5::Exception, without the file's name.
study read_image(const std::string& path, std::vector<char>& bytes, const study_parts_reader& read_parts) {
  if (!has_hdf5_signature(bytes)) throw std::runtime_error("not an HDF5 file");
  H5::FileAccPropList access;
  access.setCore(std::size_t{1} << 20, false);
  if (H5Pset_file_image(access.getId(), bytes.data(), bytes.size()) < 0)
    throw std::runtime_error("cannot hand its bytes to HDF5");
  // The core driver refuses a name that exists on disk when it is handed an image.
  const H5::H5File file("in-memory image of " + path, H5F_ACC_RDONLY, H5::FileCreatPropList::DEFAULT, access);
  study out;
  study_record& rec = out.record.emplace();
  rec.path = path;
  if (!file.attrExists("format_version")) throw std::runtime_error("not a stepbench study (no format_version)");
  rec.format_version = h5::long_attr(file, "format_version");
  if (rec.format_version > study_format_version)
    throw std::runtime_error(fmt::format("written by a newer stepbench (format_version {}; this build reads {} to {})",
                                         rec.format_version, study_format_read_min, study_format_version));
  if (rec.format_version < study_format_read_min)
    throw std::runtime_error(fmt::format("format_version {} is older than this build reads ({}); run the study again",
                                         rec.format_version, study_format_read_min));
  rec.meta = h5::string_attrs(file);
  rec.settings = h5::number_attrs(file, false);
  if (h5::long_attr(file, "timing") != 0) out.timed.emplace();
  // Every study file has it, a scan file's empty (parts read their groups where present).
  if (!h5::is_group(file, "problems")) throw std::runtime_error("missing group 'problems'");
  read_parts(file, out);
  return out;
}

// HDF5 1.10 trusts sizes stored in the file where no call of its API can check them
// first (a global heap object's length when it reads a variable-length string, an
// attribute message's size when it looks an attribute up): a damaged file can make it
// copy out of bounds and crash. So the file's bytes are read first into memory and read
// by a child process; the parent reads the same bytes with the same code only when the
// child read them whole, so a damaged file never reaches HDF5 in the parent. The child's
// answer: empty when it read the study, else 'H' and an HDF5 error's detail or 'R' and
// another error's text. The children of several files run at once.
struct reading_child {
  std::string path;
  const study_parts_reader* read_parts;
  std::vector<char> bytes;
  pid_t pid = -1;
  int fd = -1;
};

// The CPU time a child may take to read one file (a whole study reads in well under a second).
constexpr long reading_cpu_seconds = 20;

std::runtime_error cannot_read(const std::string& path, const std::string& what) {
  return std::runtime_error(fmt::format("cannot read study file '{}': {}", path, what));
}

// The largest file taken for a study: the default study's file is about 10 MB, a large
// merged or scanned one some hundreds; past this it is not a study (or not one this
// machine should hold in memory three times, as the reader does).
constexpr std::uintmax_t largest_study_file = std::uintmax_t{1} << 30;

// The file's bytes, read whole by the calling process (a regular file only: a device or a
// pipe would not end).
std::vector<char> file_bytes(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw cannot_read(path, "not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw cannot_read(path, ec.message());
  if (size > largest_study_file)
    throw cannot_read(path,
                      fmt::format("{} bytes: larger than a study file can be ({} bytes)", size, largest_study_file));
  std::vector<char> bytes(static_cast<std::size_t>(size));
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw cannot_read(path, std::strerror(errno));
  const std::size_t got = std::fread(bytes.data(), 1, bytes.size(), f);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) throw cannot_read(path, "an I/O error while reading it");
  bytes.resize(got);  // shorter when the file shrank meanwhile: the child judges what was read
  return bytes;
}

// `held`: the bytes this process holds of the files read so far, this one's included.
reading_child start_reading(const std::string& path, const study_parts_reader& read_parts, std::size_t& held) {
  reading_child c{path, &read_parts, file_bytes(path), -1, -1};
  held += c.bytes.size();
  int fds[2];
  if (::pipe(fds) != 0)
    throw cannot_read(path, fmt::format("cannot start the process that reads it: {}", std::strerror(errno)));
  std::fflush(nullptr);
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(fds[0]), ::close(fds[1]);
    throw cannot_read(path, fmt::format("cannot start the process that reads it: {}", std::strerror(errno)));
  }
  if (child == 0) {
    ::close(fds[0]);
    // Bounds on what a damaged file can make HDF5 do: a stored length it trusts makes it
    // allocate gigabytes, a damaged B-tree can make it loop. A whole study reads in well
    // under a second and a few hundred MB, so past these the file is damaged: the child
    // is stopped (SIGXCPU) or its allocation fails, and the parent says so. (Not the
    // address-space bound under AddressSanitizer, which reserves terabytes of it.)
    // The memory bound counts this file and those read before it (inherited).
    bound_child(reading_cpu_seconds, child_memory_bound(held));
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    std::string answer;
    try {
      read_image(path, c.bytes, read_parts);
    } catch (const H5::Exception& e) {
      answer = "H" + e.getDetailMsg();
    } catch (const std::exception& e) {
      answer = std::string("R") + e.what();
    }
    write_bytes(fds[1], answer.data(), answer.size());  // failing when the parent is gone: nothing to tell
    std::_Exit(0);
  }
  ::close(fds[1]);
  c.pid = child;
  c.fd = fds[0];
  return c;
}

// The study, once the child has read it whole; throws the line read_study prints.
study finish_reading(reading_child& c) {
  const auto fail = [&](const std::string& what) { return cannot_read(c.path, what); };
  const std::string answer = read_to_end(c.fd);
  ::close(c.fd);
  c.fd = -1;
  int status = 0;
  while (::waitpid(c.pid, &status, 0) < 0)
    if (errno != EINTR) throw fail(fmt::format("cannot wait for the process that reads it: {}", std::strerror(errno)));
  c.pid = -1;
  // How the child ended when it did not end normally: a signal ("SIGSEGV"), or a
  // sanitizer's report ("exit 1").
  if (WIFSIGNALED(status) || WEXITSTATUS(status) != 0)
    throw fail(abnormal_end(status, reading_cpu_seconds, "reading it"));
  if (!answer.empty() && answer[0] == 'H')
    throw fail(fmt::format("HDF5: {} (truncated or corrupt?)", answer.substr(1)));
  if (!answer.empty()) throw fail(answer.substr(1));
  try {  // the same bytes, with the same code, that the child read whole
    return read_image(c.path, c.bytes, *c.read_parts);
  } catch (const H5::Exception& e) {
    throw fail(fmt::format("HDF5: {}", e.getDetailMsg()));
  } catch (const std::exception& e) {
    throw fail(e.what());
  }
}

// Children still running when reading stops early (an error in an earlier file) are
// stopped and reaped.
struct reading_children {
  std::vector<reading_child> all;
  ~reading_children() {
    for (auto& c : all) {
      if (c.fd >= 0) ::close(c.fd);
      if (c.pid > 0) {
        ::kill(c.pid, SIGKILL);
        while (::waitpid(c.pid, nullptr, 0) < 0 && errno == EINTR) {
        }
      }
    }
  }
};

}  // namespace

std::vector<study> read_studies(const std::vector<std::string>& paths, const study_parts_reader& read_parts) {
  for (const auto& path : paths) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw cannot_read(path, "no such file");
    if (std::filesystem::is_directory(path, ec)) throw cannot_read(path, "it is a directory");
  }
  H5::Exception::dontPrint();
  reading_children children;
  std::size_t held = 0;
  for (const auto& path : paths) children.all.push_back(start_reading(path, read_parts, held));
  std::vector<study> out;
  for (auto& c : children.all) out.push_back(finish_reading(c));
  return out;
}

}  // namespace stepbench
