#include "tools/output.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <unordered_map>

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

namespace {

// A key that two paths share exactly when they name one file (SameFile): the device and inode
// of an existing file, else the absolute path with "." and ".." and the symbolic links of its
// existing part resolved.
std::string FileKey(const std::string& path) {
  struct stat s {};
  if (::stat(path.c_str(), &s) == 0) {
    return "inode " + std::to_string(s.st_dev) + ":" + std::to_string(s.st_ino);
  }
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  if (ec) return "path " + fs::path(path).lexically_normal().string();
  const fs::path canonical = fs::weakly_canonical(absolute, ec);
  return "path " + (ec ? absolute.lexically_normal() : canonical).string();
}

}  // namespace

bool SameFile(const std::string& a, const std::string& b) { return FileKey(a) == FileKey(b); }

void CheckDistinctFiles(const std::vector<NamedFile>& inputs,
                        const std::vector<NamedFile>& outputs) {
  std::unordered_map<std::string, const NamedFile*> inputs_by_key, outputs_by_key;
  for (const NamedFile& in : inputs) {
    if (!in.path.empty()) inputs_by_key.emplace(FileKey(in.path), &in);
  }
  for (const NamedFile& out : outputs) {
    if (out.path.empty() || IsStreamOutput(out.path)) continue;
    const std::string key = FileKey(out.path);
    const auto [it, added] = outputs_by_key.emplace(key, &out);
    if (!added) {
      const NamedFile& other = *it->second;
      throw UsageError(other.option + " and " + out.option + " name the same file ('" + other.path +
                       "', '" + out.path + "'); give each output its own file");
    }
    if (const auto in = inputs_by_key.find(key); in != inputs_by_key.end()) {
      throw UsageError(out.option + " '" + out.path + "' names the input " + in->second->option +
                       " '" + in->second->path + "'; an output may not overwrite an input");
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
