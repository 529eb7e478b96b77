#include "tools/output.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "tools/options.h"

namespace hybrid::cli {
namespace {

namespace fs = std::filesystem;

// The directory an output file is written into ("." for a bare name).
fs::path DirectoryOf(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

std::string Reason(int error) { return error != 0 ? std::string(": ") + std::strerror(error) : ""; }

// Writes `text` into an existing stream output (standard output, a device, a FIFO).
void WriteStream(const std::string& path, const std::string& text) {
  if (path.empty() || path == "-") {
    std::cout << text;
    std::cout.flush();
    if (!std::cout) throw OutputError("cannot write to standard output");
    return;
  }
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.flush();
  if (!out) throw OutputError("cannot write '" + path + "'");
}

// Writes `text` to a new temporary file next to `target` and returns its path.
std::string WriteTemporary(const std::string& target, const std::string& text, int index) {
  const fs::path t(target);
  const std::string temp =
      (DirectoryOf(target) / ("." + t.filename().string() + ".tmp-" + std::to_string(::getpid()) +
                              "-" + std::to_string(index)))
          .string();
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw OutputError("cannot write '" + target + "'" + Reason(errno));
  std::size_t written = 0;
  int error = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      error = n < 0 ? errno : EIO;
      break;
    }
    written += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    ::unlink(temp.c_str());
    throw OutputError("cannot write '" + target + "'" + Reason(error));
  }
  return temp;
}

// Creates `dir` and its missing parents; appends the directories it created to `created`,
// outermost first. Throws OutputError.
void CreateDirectories(const std::string& dir, std::vector<fs::path>* created) {
  std::vector<fs::path> missing;
  std::error_code ec;
  for (fs::path p = fs::path(dir).lexically_normal(); !p.empty() && !fs::exists(p, ec);
       p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (!fs::create_directory(*it, ec) && ec) {
      throw OutputError("cannot create the directory '" + it->string() + "': " + ec.message());
    }
    created->push_back(*it);
  }
  if (!fs::is_directory(dir, ec)) {
    throw OutputError("cannot create the directory '" + dir +
                      "': it exists and is not a directory");
  }
}

}  // namespace

bool IsStreamOutput(const std::string& path) {
  if (path.empty() || path == "-") return true;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  return fs::exists(status) && !fs::is_regular_file(status) && !fs::is_directory(status);
}

bool SameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) {
    const bool same = fs::equivalent(a, b, ec);
    if (!ec) return same;
  }
  const fs::path pa = fs::weakly_canonical(fs::absolute(a, ec), ec);
  if (ec) return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
  const fs::path pb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  if (ec) return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
  return pa == pb;
}

void CheckDistinctFiles(const std::vector<NamedFile>& inputs,
                        const std::vector<NamedFile>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const NamedFile& out = outputs[i];
    if (out.path.empty() || IsStreamOutput(out.path)) continue;
    for (std::size_t j = 0; j < i; ++j) {
      const NamedFile& other = outputs[j];
      if (other.path.empty() || IsStreamOutput(other.path)) continue;
      if (SameFile(out.path, other.path)) {
        throw UsageError(other.option + " and " + out.option + " name the same file ('" +
                         other.path + "', '" + out.path + "'); give each output its own file");
      }
    }
    for (const NamedFile& in : inputs) {
      if (in.path.empty()) continue;
      if (SameFile(out.path, in.path)) {
        throw UsageError(out.option + " '" + out.path + "' names the input " + in.option + " '" +
                         in.path + "'; an output may not overwrite an input");
      }
    }
  }
}

void CheckOutputPlaces(const std::vector<NamedFile>& files,
                       const std::vector<NamedFile>& directories) {
  std::error_code ec;
  for (const NamedFile& f : files) {
    if (f.path.empty() || IsStreamOutput(f.path)) continue;
    const fs::path dir = DirectoryOf(f.path);
    if (!fs::is_directory(dir, ec)) {
      throw OutputError("cannot write " + f.option + " '" + f.path + "': the directory '" +
                        dir.string() +
                        (fs::exists(dir, ec) ? "' is not a directory" : "' does not exist"));
    }
    if (fs::is_directory(f.path, ec)) {
      throw OutputError("cannot write " + f.option + " '" + f.path + "': it is a directory");
    }
  }
  for (const NamedFile& d : directories) {
    if (d.path.empty()) continue;
    // The nearest existing ancestor (or the directory itself) must be a directory.
    fs::path p = fs::path(d.path).lexically_normal();
    while (!p.empty() && !fs::exists(p, ec) && p != p.parent_path()) p = p.parent_path();
    if (p.empty()) continue;  // a relative path whose first part is new: created in "."
    if (!fs::is_directory(p, ec)) {
      throw OutputError("cannot create " + d.option + " '" + d.path + "': '" + p.string() +
                        "' exists and is not a directory");
    }
  }
}

void WriteOutput(const std::string& path, const std::string& text) { WriteOutputs({{path, text}}); }

void WriteOutputs(const std::vector<std::pair<std::string, std::string>>& files,
                  const std::vector<std::string>& directories) {
  std::vector<NamedFile> named;
  for (const auto& [path, text] : files) named.push_back({"'" + path + "'", path});
  CheckDistinctFiles({}, named);
  std::vector<fs::path> created;                             // directories, outermost first
  std::vector<std::pair<std::string, std::string>> renames;  // (temporary, target)
  auto discard = [&]() {
    std::error_code ignored;
    for (const auto& r : renames) fs::remove(r.first, ignored);
    for (auto it = created.rbegin(); it != created.rend(); ++it) fs::remove(*it, ignored);
  };
  try {
    for (const std::string& dir : directories) CreateDirectories(dir, &created);
    int index = 0;
    for (const auto& [path, text] : files) {
      if (IsStreamOutput(path)) continue;
      std::error_code ec;
      if (fs::is_directory(path, ec)) {
        throw OutputError("cannot write '" + path + "': it is a directory");
      }
      renames.emplace_back(WriteTemporary(path, text, index++), path);
    }
    for (const auto& [path, text] : files) {
      if (IsStreamOutput(path)) WriteStream(path, text);
    }
  } catch (const OutputError&) {
    discard();
    throw;
  }
  for (std::size_t i = 0; i < renames.size(); ++i) {
    std::error_code ec;
    fs::rename(renames[i].first, renames[i].second, ec);
    if (ec) {
      // Not expected (same directory, target not a directory): the files renamed so far stay.
      std::error_code ignored;
      for (std::size_t k = i; k < renames.size(); ++k) fs::remove(renames[k].first, ignored);
      throw OutputError("cannot write '" + renames[i].second + "': " + ec.message());
    }
  }
}

}  // namespace hybrid::cli
