#include <meccano/atomic_file.hpp>

#include <meccano/error.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include <unistd.h>

namespace meccano {

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  // Renaming over a device or a FIFO (as root, /dev/full or /dev/null) would replace it: refuse.
  std::error_code status_error;
  const fs::file_status status = fs::status(target, status_error);
  if (fs::exists(status) && !fs::is_regular_file(status))
    throw InputError("cannot write " + path + ": not a regular file");
  fs::path temporary = target;
  temporary += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(std::random_device{}());
  auto fail = [&](const std::string& reason) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw InputError("cannot write " + path + ": " + reason);
  };
  {
    std::vector<char> buffer(1 << 20);  // declared first: it must outlive the stream
    std::ofstream out;
    out.rdbuf()->pubsetbuf(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    out.open(temporary, std::ios::binary);
    if (!out) fail(std::strerror(errno));
    try {
      write(out);
    } catch (...) {
      out.close();
      std::error_code ignored;
      fs::remove(temporary, ignored);
      throw;
    }
    out.flush();
    if (!out) fail(errno ? std::strerror(errno) : "write failed");
    out.close();
    if (!out) fail(errno ? std::strerror(errno) : "close failed");
  }
  std::error_code error;
  fs::rename(temporary, target, error);
  if (error) fail(error.message());
}

}  // namespace meccano
