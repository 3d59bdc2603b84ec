#include <meccano/io/atomic_file.hpp>

#include <meccano/error.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include <unistd.h>

namespace meccano {

namespace fs = std::filesystem;

namespace {

// Renaming over a device or a FIFO (as root, /dev/full or /dev/null) would replace it: refuse.
void require_regular_or_absent(const std::string& path) {
  std::error_code status_error;
  const fs::file_status status = fs::status(fs::path(path), status_error);
  if (fs::exists(status) && !fs::is_regular_file(status))
    throw InputError("cannot write " + path + ": not a regular file");
}

// A path next to `target` that no other process or call picks, with the same extension (writers such
// as write_mesh choose the format by it): a.msh -> a.tmp<pid>-<random>.msh.
fs::path temporary_beside(const std::string& target) {
  const fs::path path(target);
  fs::path temporary = path.parent_path() / path.stem();
  temporary += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(std::random_device{}());
  temporary += path.extension();
  return temporary;
}

}  // namespace

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  require_regular_or_absent(path);
  const fs::path target(path);
  const fs::path temporary = temporary_beside(path);
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

void require_writable(const std::string& path) {
  std::error_code status_error;
  if (fs::is_directory(fs::path(path), status_error)) throw InputError("cannot write " + path + ": it is a directory");
  require_regular_or_absent(path);
  const fs::path parent = fs::path(path).parent_path();
  const fs::path directory = parent.empty() ? fs::path(".") : parent;
  if (!fs::is_directory(directory, status_error))
    throw InputError("cannot write " + path + ": there is no directory " + directory.string());
  // Writing creates a temporary beside the target and renames it: the directory must be writable.
  if (::access(directory.c_str(), W_OK | X_OK) != 0)
    throw InputError("cannot write " + path + ": " + directory.string() + ": " + std::strerror(errno));
}

StagedFiles::~StagedFiles() {
  for (const auto& [staged, target] : staged_) {
    std::error_code ignored;
    fs::remove(staged, ignored);
  }
}

void StagedFiles::write(const std::string& target, const std::function<void(const std::string& path)>& writer) {
  require_regular_or_absent(target);
  const std::string staged = temporary_beside(target).string();
  staged_.emplace_back(staged, target);
  try {
    writer(staged);
  } catch (const InputError& error) {
    std::string message = error.what();
    for (auto at = message.find(staged); at != std::string::npos; at = message.find(staged, at + target.size()))
      message.replace(at, staged.size(), target);
    throw InputError(message);
  }
}

void StagedFiles::commit() {
  while (!staged_.empty()) {
    const auto [staged, target] = staged_.front();
    std::error_code error;
    fs::rename(staged, target, error);
    if (error) throw InputError("cannot write " + target + ": " + error.message());  // the rest go with *this
    staged_.erase(staged_.begin());
  }
}

}  // namespace meccano
