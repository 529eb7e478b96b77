#pragma once

#include <filesystem>
#include <string>

namespace hybrid::cli {

/// The file `relative` (e.g. "spec/finger.ha") of the models and data bundled with `hybrid`,
/// found without any path compiled into the program, in this order:
/// 1. under $HYBRID_DATA_DIR, when that variable is set (and the file exists there);
/// 2. under DIR/../share/hybrid, DIR the directory of the running executable: the install
///    layout (PREFIX/bin/hybrid, PREFIX/share/hybrid/) and the build tree (BUILD/bin/hybrid,
///    BUILD/share/hybrid/ links to the source's spec/ and data/, so edits there are seen);
/// 3. the copy of spec/*.ha built into the executable (a binary copied anywhere), written once
///    to $XDG_CACHE_HOME/hybrid/bundled-VERSION-HASH/ (default ~/.cache; /tmp when neither
///    HOME nor XDG_CACHE_HOME is set), so that imports between them and messages naming their
///    lines work as for any file.
/// Throws OptionError about "model" ("the bundled file ... was not found ...; pass model FILE",
/// the argument as each front end names it) when none of these has it.
std::filesystem::path BundledFile(const std::string& relative);

/// The directory of the running executable (from /proc/self/exe); empty if unknown.
std::filesystem::path ExecutableDirectory();

}  // namespace hybrid::cli
