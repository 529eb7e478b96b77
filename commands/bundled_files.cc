#include "commands/bundled_files.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <functional>
#include <string_view>
#include <system_error>

#include "commands/bundled_data.h"
#include "commands/command_error.h"

namespace hybrid::cli {
namespace {

namespace fs = std::filesystem;

bool IsFile(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

// Where the built-in copies are written: a folder named after the program's version and the
// copies' content, so that two versions never share one.
fs::path CacheFolder() {
  std::size_t hash = 0;
  for (const BundledEntry& e : BundledEntries()) {
    hash = hash * 31 + std::hash<std::string_view>{}(e.path) * 7 +
           std::hash<std::string_view>{}(e.content);
  }
  fs::path base;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg == '/') {
    base = xdg;
  } else if (const char* home = std::getenv("HOME"); home != nullptr && *home == '/') {
    base = fs::path(home) / ".cache";
  } else {
    base = fs::temp_directory_path();
  }
  return base / "hybrid" / ("bundled-" HYBRID_VERSION "-" + std::to_string(hash));
}

// Writes every built-in copy under `folder` (through a temporary folder renamed into place, so
// that a concurrent run never reads half a file). False when that fails.
bool WriteBuiltInCopies(const fs::path& folder) {
  std::error_code ec;
  if (fs::is_directory(folder, ec)) return true;
  const fs::path temporary = folder.string() + ".tmp" + std::to_string(::getpid());
  fs::create_directories(temporary, ec);
  if (ec) return false;
  for (const BundledEntry& e : BundledEntries()) {
    const fs::path file = temporary / fs::path(std::string(e.path));
    fs::create_directories(file.parent_path(), ec);
    std::ofstream out(file, std::ios::binary);
    out.write(e.content.data(), static_cast<std::streamsize>(e.content.size()));
    if (ec || !out) {
      fs::remove_all(temporary, ec);
      return false;
    }
  }
  fs::rename(temporary, folder, ec);
  if (ec) fs::remove_all(temporary, ec);  // another run put its copy there first
  return fs::is_directory(folder, ec);
}

bool IsBuiltIn(const std::string& relative) {
  for (const BundledEntry& e : BundledEntries()) {
    if (e.path == relative) return true;
  }
  return false;
}

}  // namespace

fs::path ExecutableDirectory() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

fs::path BundledFile(const std::string& relative) {
  if (const char* dir = std::getenv("HYBRID_DATA_DIR"); dir != nullptr && *dir != '\0') {
    if (const fs::path p = fs::path(dir) / relative; IsFile(p)) return p;
  }
  if (const fs::path exe = ExecutableDirectory(); !exe.empty()) {
    const fs::path p = exe.parent_path() / "share" / "hybrid" / relative;
    if (IsFile(p)) return p.lexically_normal();
  }
  if (IsBuiltIn(relative)) {
    const fs::path folder = CacheFolder();
    if (WriteBuiltInCopies(folder) && IsFile(folder / relative)) return folder / relative;
  }
  throw OptionError("model", "the bundled file '" + relative +
                                 "' was not found (next to the program in ../share/hybrid/, under "
                                 "$HYBRID_DATA_DIR, or in a cache folder for its built-in copy); "
                                 "pass " +
                                 Arg("model") + " FILE");
}

}  // namespace hybrid::cli
