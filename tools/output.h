#pragma once

#include <stdexcept>
#include <string>

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

}  // namespace hybrid::cli
