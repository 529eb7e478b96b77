#pragma once

// The files a `hybrid` command writes (docs/cli.md, "Output files"): checked before any work
// (no two outputs naming one file, no output naming an input, every output's directory present),
// then written all or nothing.

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace hybrid::cli {

/// An output file or standard output could not be written (exit code 3).
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A file named on the command line: the option that names it ("MODEL" for a positional
/// argument, "--out", ...) and its path.
struct NamedFile {
  std::string option;
  std::string path;
};

/// Whether `path` is standard output ("" or "-") or an existing file that is neither a regular
/// file nor a directory (a device such as /dev/null or /dev/stdout, a FIFO): outputs written
/// directly, never through a temporary file, and never compared by CheckDistinctFiles.
bool IsStreamOutput(const std::string& path);

/// Whether `a` and `b` name one file: std::filesystem::equivalent when both exist, otherwise
/// equal absolute paths after resolving the symbolic links of their existing parts and
/// normalising "." and ".." (std::filesystem::weakly_canonical).
bool SameFile(const std::string& a, const std::string& b);

/// Throws UsageError (tools/options.h; exit 2) naming both options when two `outputs` name one
/// file (SameFile) or an output names one of the `inputs`. Outputs for which IsStreamOutput holds
/// are not compared; entries with an empty path are skipped.
void CheckDistinctFiles(const std::vector<NamedFile>& inputs,
                        const std::vector<NamedFile>& outputs);

/// The cheap checks of the outputs that can be made before any work. Throws OutputError (exit 3)
/// when the directory of an output file (its parent, "." for a bare name) does not exist or is
/// not a directory (output files never create directories), or when an output directory
/// (`directories`, created with its parents when the command writes) is an existing non-directory
/// or lies below one. Stream outputs (IsStreamOutput) are not checked.
void CheckOutputPlaces(const std::vector<NamedFile>& files,
                       const std::vector<NamedFile>& directories = {});

/// Writes `text` to `path` all or nothing (WriteOutputs with one file); "-" or "" writes to
/// standard output; a stream output (IsStreamOutput) is written directly. Throws OutputError.
void WriteOutput(const std::string& path, const std::string& text);

/// Writes several files all or nothing. First the `directories` are created with their missing
/// parents; then every text for a regular (or new) file goes to a new temporary file
/// (".NAME.tmp-PID-K") in its target's directory, and stream outputs (IsStreamOutput) are
/// written directly; only when all of that succeeded are the temporary files renamed over their
/// targets. On a failure the temporary files and the directories this call created are removed
/// and no regular target is touched (existing files keep their content), then OutputError is
/// thrown. Two entries naming one file (SameFile) are refused with UsageError before anything is
/// written.
void WriteOutputs(const std::vector<std::pair<std::string, std::string>>& files,
                  const std::vector<std::string>& directories = {});

}  // namespace hybrid::cli
