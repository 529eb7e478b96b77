#pragma once

#include <span>
#include <string_view>

namespace hybrid::cli {

/// One file bundled into the executable: its path under the bundle (e.g. "spec/finger.ha") and
/// its bytes.
struct BundledEntry {
  std::string_view path;
  std::string_view content;
};

/// The copies of spec/*.ha made at build time (commands/embed_files.cmake writes the definition).
std::span<const BundledEntry> BundledEntries();

}  // namespace hybrid::cli
