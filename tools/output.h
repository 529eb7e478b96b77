#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace hybrid::cli {

/// An output file or standard output could not be written (exit code 3).
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Writes `text` to `path` atomically (temporary file in the same directory, then rename), so a
/// failed run never leaves a partial file; "-" or "" writes to standard output; an existing
/// target that is not a regular file (a device such as /dev/stdout, a FIFO) is written directly.
/// Throws OutputError.
void WriteOutput(const std::string& path, const std::string& text);

/// Writes several files all or nothing: every text for a regular (or new) file goes to a
/// temporary file next to its target first; only when all are written (and the outputs that
/// cannot be renamed over, "-" and devices, have been written directly) are they renamed into
/// place. If one cannot be written, the temporaries are removed and no regular target is touched
/// (existing files keep their content). Throws OutputError.
void WriteOutputs(const std::vector<std::pair<std::string, std::string>>& files);

}  // namespace hybrid::cli
