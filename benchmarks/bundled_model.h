#pragma once

#include <filesystem>
#include <string>

namespace hybrid::benchmarks {

/// spec/NAME as the build tree bundles it: BUILD/share/hybrid/spec/NAME, found from this
/// program's place (BUILD/benchmarks/), like `hybrid` finds it (commands/bundled_files.h).
inline std::string BundledModel(const std::string& name) {
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe");
  return (exe.parent_path().parent_path() / "share" / "hybrid" / "spec" / name).string();
}

}  // namespace hybrid::benchmarks
