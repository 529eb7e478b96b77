#pragma once

// The files a `hybrid` command writes (docs/cli.md, "Output files"): checked before any work
// (no two outputs naming one file, no output naming an input, every output's directory present),
// then written all or nothing, and no temporary file left behind when a signal stops the program.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands/command_error.h"

namespace hybrid::cli {

/// An output file or standard output could not be written (exit code 3). The message may refer
/// to the argument naming the file ("cannot write out 't.csv': ...").
class OutputError : public CommandError {
 public:
  using CommandError::CommandError;
};

/// A file a command reads or writes: the argument that names it (its API name: "model", "out",
/// "input_csv"; messages refer to it) and its path. An input the command reads because another
/// names it (a model's import) has no argument but a `role` saying so ("imported by model
/// 'main.ha'"), which messages give in its place; a file with neither is named by its path.
struct NamedFile {
  std::string argument;
  std::string path;
  ArgumentMessage role = {};
};

/// The files reading the model file `path` (named by the argument `argument`: "model") reads, as
/// inputs for CheckDistinctFiles: the model itself; every file it imports, directly or through
/// other imports, found as the parser finds them (`import "FILE";` outside comments, FILE relative
/// to the importing file's directory), with the role "imported by ..."; and for a SpaceEx model
/// (.xml) its configuration: `config` if given, else the .cfg beside it if it exists, with the
/// role "the SpaceEx configuration of ...". Nothing is read from a model that is not a regular
/// file (a pipe, /dev/stdin: reading it would consume it); a file that cannot be read, an import
/// that does not exist and a cycle are skipped (reading the model reports them). Never throws
/// for a bad model.
std::vector<NamedFile> ModelInputs(const std::string& argument, const std::string& path,
                                   const std::optional<std::string>& config = std::nullopt);

/// Whether `path` is standard output ("" or "-") or an existing file that is neither a regular
/// file nor a directory (a device such as /dev/null or /dev/stdout, a FIFO): outputs written
/// directly, never through a temporary file, and never compared by CheckDistinctFiles.
bool IsStreamOutput(const std::string& path);

/// Whether `a` and `b` name one file: std::filesystem::equivalent when both exist, otherwise
/// equal absolute paths after resolving the symbolic links of their existing parts and
/// normalising "." and ".." (std::filesystem::weakly_canonical).
bool SameFile(const std::string& a, const std::string& b);

/// Throws OptionError (commands/command_error.h; exit 2) about the later output, referring to both
/// arguments, when two `outputs` name one file (SameFile) or an output names one of the `inputs`
/// (named by its argument, or by its path and role). Outputs for which IsStreamOutput holds are not
/// compared; entries with an empty path are skipped.
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
/// thrown. Two entries naming one file (SameFile) are refused with OptionError before anything is
/// written. While they exist, the temporary files and the created directories are registered with
/// RemovedOnSignal, and the renames run with SIGINT, SIGTERM and SIGHUP blocked in the calling
/// thread: a program stopped by one of them (RemoveTemporaryFilesOnSignals) leaves either no
/// temporary file and no target touched, or (stopped during the renames) every target written.
void WriteOutputs(const std::vector<std::pair<std::string, std::string>>& files,
                  const std::vector<std::string>& directories = {});

/// Installs handlers of SIGINT, SIGTERM and SIGHUP (those not ignored when it is called) that
/// remove every path registered with RemovedOnSignal (files with unlink(2), then directories with
/// rmdir(2), the latest registered first) and then end the program by the same signal with its
/// default action (so the exit status tells the signal, as without the handlers). The handlers are
/// async-signal-safe. Call it once, early in main; a library (the Python module) does not.
void RemoveTemporaryFilesOnSignals();

/// While it lives, `path` (a file, or an empty directory with kDirectory) is removed if one of the
/// signals of RemoveTemporaryFilesOnSignals stops the program. Register a file before creating it
/// (removing a path not created yet is harmless) and let the registration go once the file is
/// renamed or removed. At most 64 paths are registered at once and a path may be at most 4095
/// bytes long; beyond that nothing is registered (the path is then not removed on a signal).
/// Relative paths are taken from the working directory at the signal.
class RemovedOnSignal {
 public:
  enum Kind { kFile, kDirectory };
  RemovedOnSignal(const std::string& path, Kind kind = kFile);
  ~RemovedOnSignal();
  RemovedOnSignal(RemovedOnSignal&& other) noexcept : slot_(other.slot_) { other.slot_ = -1; }
  RemovedOnSignal& operator=(RemovedOnSignal&&) = delete;
  RemovedOnSignal(const RemovedOnSignal&) = delete;
  RemovedOnSignal& operator=(const RemovedOnSignal&) = delete;

  /// Whether the path is registered (false when the table was full or the path too long).
  bool registered() const { return slot_ >= 0; }

 private:
  int slot_ = -1;  // index in the table of registered paths; -1: none
};

}  // namespace hybrid::cli
