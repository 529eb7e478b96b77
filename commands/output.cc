#include "commands/output.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <string_view>
#include <unordered_map>

#include "commands/command_error.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/spaceex/spaceex_import.h"

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

// ---------------------------------------------------------------------------------------------
// The paths removed when a signal stops the program (RemovedOnSignal): a fixed table, so that the
// signal handler reads it without allocating or locking. A slot is free, being filled (its path
// not yet complete: the handler skips it), or holds a file or a directory.

constexpr int kFreeSlot = 0, kFillingSlot = 1, kFileSlot = 2, kDirectorySlot = 3;
constexpr std::size_t kSlots = 64;
constexpr std::size_t kMaxRegisteredPath = 4096;  // bytes, with the terminating NUL

struct RegisteredPath {
  std::atomic<int> state{kFreeSlot};
  char path[kMaxRegisteredPath] = {};
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads the table");

std::array<RegisteredPath, kSlots> registered_paths;

constexpr std::array<int, 3> kCleanedSignals = {SIGINT, SIGTERM, SIGHUP};

// Removes the registered files, then the directories (latest slot first: a directory is
// registered before what it holds), then ends the program by `signal` (reset to its default
// action by SA_RESETHAND; raised again, it is delivered when the handler returns). Uses only
// async-signal-safe calls.
extern "C" void RemoveRegisteredAndRaise(int signal) {
  for (const RegisteredPath& r : registered_paths) {
    if (r.state.load(std::memory_order_acquire) == kFileSlot) ::unlink(r.path);
  }
  for (auto r = registered_paths.rbegin(); r != registered_paths.rend(); ++r) {
    if (r->state.load(std::memory_order_acquire) == kDirectorySlot) ::rmdir(r->path);
  }
  ::raise(signal);
}

// SIGINT, SIGTERM and SIGHUP blocked in the calling thread while it lives (pending ones are
// delivered when it ends).
class BlockedSignals {
 public:
  BlockedSignals() {
    sigset_t set;
    sigemptyset(&set);
    for (int s : kCleanedSignals) sigaddset(&set, s);
    blocked_ = pthread_sigmask(SIG_BLOCK, &set, &previous_) == 0;
  }
  ~BlockedSignals() {
    if (blocked_) pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
  }
  BlockedSignals(const BlockedSignals&) = delete;
  BlockedSignals& operator=(const BlockedSignals&) = delete;

 private:
  sigset_t previous_{};
  bool blocked_ = false;
};

// The name of the temporary file written for `target` (".NAME.tmp-PID-K" next to it).
std::string TemporaryName(const std::string& target, int index) {
  return (DirectoryOf(target) / ("." + fs::path(target).filename().string() + ".tmp-" +
                                 std::to_string(::getpid()) + "-" + std::to_string(index)))
      .string();
}

// Writes `text` to the new temporary file `temp` (registered with RemovedOnSignal by the caller)
// for `target`. Throws OutputError.
void WriteTemporary(const std::string& target, const std::string& temp, const std::string& text) {
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
}

// Creates `dir` and its missing parents; appends the directories it created to `created`,
// outermost first, and registers each with RemovedOnSignal in `registrations`. Throws
// OutputError.
void CreateDirectories(const std::string& dir, std::vector<fs::path>* created,
                       std::vector<RemovedOnSignal>* registrations) {
  std::vector<fs::path> missing;
  std::error_code ec;
  for (fs::path p = fs::path(dir).lexically_normal(); !p.empty() && !fs::exists(p, ec);
       p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    registrations->emplace_back(it->string(), RemovedOnSignal::kDirectory);
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

namespace {

// The file names `text` imports (`import "FILE";`), in order. Comments run from '#' to the end of
// the line and strings appear only after `import` (docs/model_language.md, "Lexical rules"); a
// malformed rest is left to the parser.
std::vector<std::string> ImportedNames(std::string_view text) {
  std::vector<std::string> names;
  bool after_import = false;  // the last token was the keyword `import`
  std::size_t i = 0;
  while (i < text.size()) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '#') {
      i = text.find('\n', i);
    } else if (std::isspace(c)) {
      ++i;
    } else if (c == '"') {
      const std::size_t end = text.find_first_of("\"\n\r", i + 1);
      if (end == std::string_view::npos || text[end] != '"') break;
      if (after_import) names.emplace_back(text.substr(i + 1, end - i - 1));
      after_import = false;
      i = end + 1;
    } else if (std::isalpha(c) || c == '_') {
      std::size_t end = i;
      while (end < text.size() &&
             (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_')) {
        ++end;
      }
      after_import = text.substr(i, end - i) == "import";
      i = end;
    } else {
      after_import = false;
      ++i;
    }
  }
  return names;
}

// The first kMaxModelFileBytes + 1 bytes of the regular file `path` (more are refused by the
// parser anyway), or nullopt when it is not a regular file or cannot be read.
std::optional<std::string> RegularFileText(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return std::nullopt;
  const std::uintmax_t size = fs::file_size(path, ec);
  std::ifstream in(path, std::ios::binary);
  if (ec || !in) return std::nullopt;
  std::string text(std::min<std::uintmax_t>(size, kMaxModelFileBytes + 1), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  return text;
}

// Appends to `inputs` the files `file` imports and theirs, each once (`seen`: canonical paths),
// as the parser resolves them (relative to the importing file's directory); `by` describes the
// importer of the top-level file's imports.
void CollectImports(const fs::path& file, const ArgumentMessage& by, int depth,
                    std::set<fs::path>* seen, std::vector<NamedFile>* inputs) {
  if (depth > kMaxImportDepth) return;
  const std::optional<std::string> text = RegularFileText(file);
  if (!text) return;
  for (const std::string& name : ImportedNames(*text)) {
    const fs::path imported = file.parent_path() / name;
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(imported, ec);
    if (ec || !seen->insert(canonical).second) continue;
    inputs->push_back({"", imported.string(), "imported by " + by});
    CollectImports(imported, "'" + imported.string() + "'", depth + 1, seen, inputs);
  }
}

}  // namespace

std::vector<NamedFile> ModelInputs(const std::string& argument, const std::string& path,
                                   const std::optional<std::string>& config) {
  std::vector<NamedFile> inputs = {{argument, path}};
  if (path.empty()) return inputs;
  const ArgumentMessage named = Arg(argument) + " '" + path + "'";
  if (spaceex::IsSpaceExFile(path)) {
    std::optional<std::string> cfg = config;
    if (!cfg) {
      if (const auto beside = spaceex::DefaultConfigFile(path)) cfg = beside->string();
    }
    if (cfg) inputs.push_back({"", *cfg, "the SpaceEx configuration of " + named});
    return inputs;
  }
  std::error_code ec;
  std::set<fs::path> seen = {fs::weakly_canonical(path, ec)};
  CollectImports(path, named, 1, &seen, &inputs);
  return inputs;
}

namespace {

// How messages name `file`: by its argument, else by its path and role, else by its path.
ArgumentMessage NameOf(const NamedFile& file) {
  if (!file.argument.empty()) return Arg(file.argument);
  if (!file.role.empty()) return "'" + file.path + "' (" + file.role + ")";
  return "'" + file.path + "'";
}

}  // namespace

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
      throw OptionError(out.argument, NameOf(other) + " and " + NameOf(out) +
                                          " name the same file ('" + other.path + "', '" +
                                          out.path + "'); give each output its own file");
    }
    if (const auto in = inputs_by_key.find(key); in != inputs_by_key.end()) {
      const NamedFile& input = *in->second;
      const ArgumentMessage named =
          input.argument.empty() ? NameOf(input) : NameOf(input) + " '" + input.path + "'";
      throw OptionError(out.argument, NameOf(out) + " '" + out.path + "' names the input " + named +
                                          "; an output may not overwrite an input");
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
      throw OutputError("cannot write " + NameOf(f) + " '" + f.path + "': the directory '" +
                        dir.string() +
                        (fs::exists(dir, ec) ? "' is not a directory" : "' does not exist"));
    }
    if (fs::is_directory(f.path, ec)) {
      throw OutputError("cannot write " + NameOf(f) + " '" + f.path + "': it is a directory");
    }
  }
  for (const NamedFile& d : directories) {
    if (d.path.empty()) continue;
    // The nearest existing ancestor (or the directory itself) must be a directory.
    fs::path p = fs::path(d.path).lexically_normal();
    while (!p.empty() && !fs::exists(p, ec) && p != p.parent_path()) p = p.parent_path();
    if (p.empty()) continue;  // a relative path whose first part is new: created in "."
    if (!fs::is_directory(p, ec)) {
      throw OutputError("cannot create " + NameOf(d) + " '" + d.path + "': '" + p.string() +
                        "' exists and is not a directory");
    }
  }
}

void WriteOutput(const std::string& path, const std::string& text) { WriteOutputs({{path, text}}); }

namespace {

// The temporary files of one WriteOutputs call and the directories it created, registered with
// RemovedOnSignal while they exist.
struct PendingOutputs {
  std::vector<fs::path> created;                             // directories, outermost first
  std::vector<std::pair<std::string, std::string>> renames;  // (temporary, target)
  std::vector<RemovedOnSignal> registrations;

  // Removes the temporary files and the created directories.
  void Discard() {
    std::error_code ignored;
    for (const auto& r : renames) fs::remove(r.first, ignored);
    for (auto it = created.rbegin(); it != created.rend(); ++it) fs::remove(*it, ignored);
  }
};

// Creates the `directories`, writes each regular (or new) file's text to a temporary file and the
// stream outputs directly. Throws OutputError (what was made stays in `pending`).
void WriteTemporaries(const std::vector<std::pair<std::string, std::string>>& files,
                      const std::vector<std::string>& directories, PendingOutputs* pending) {
  for (const std::string& dir : directories) {
    CreateDirectories(dir, &pending->created, &pending->registrations);
  }
  int index = 0;
  for (const auto& [path, text] : files) {
    if (IsStreamOutput(path)) continue;
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
      throw OutputError("cannot write '" + path + "': it is a directory");
    }
    const std::string temp = TemporaryName(path, index++);
    pending->registrations.emplace_back(temp);  // before the file exists
    WriteTemporary(path, temp, text);
    pending->renames.emplace_back(temp, path);
  }
  for (const auto& [path, text] : files) {
    if (IsStreamOutput(path)) WriteStream(path, text);
  }
}

// Renames the temporary files over their targets, with the cleaned signals blocked, and ends the
// registrations before they are delivered. Throws OutputError.
void RenameTemporaries(PendingOutputs* pending) {
  const BlockedSignals blocked;
  for (std::size_t i = 0; i < pending->renames.size(); ++i) {
    std::error_code ec;
    fs::rename(pending->renames[i].first, pending->renames[i].second, ec);
    if (ec) {
      // Not expected (same directory, target not a directory): the files renamed so far stay.
      std::error_code ignored;
      for (std::size_t k = i; k < pending->renames.size(); ++k) {
        fs::remove(pending->renames[k].first, ignored);
      }
      pending->registrations.clear();
      throw OutputError("cannot write '" + pending->renames[i].second + "': " + ec.message());
    }
  }
  pending->registrations.clear();
}

}  // namespace

void WriteOutputs(const std::vector<std::pair<std::string, std::string>>& files,
                  const std::vector<std::string>& directories) {
  std::vector<NamedFile> named;
  for (const auto& [path, text] : files) named.push_back({"", path});
  CheckDistinctFiles({}, named);
  PendingOutputs pending;
  try {
    WriteTemporaries(files, directories, &pending);
  } catch (const OutputError&) {
    pending.Discard();
    throw;
  }
  RenameTemporaries(&pending);
}

RemovedOnSignal::RemovedOnSignal(const std::string& path, Kind kind) {
  if (path.empty() || path.size() >= kMaxRegisteredPath) return;
  for (std::size_t i = 0; i < registered_paths.size(); ++i) {
    RegisteredPath& r = registered_paths[i];
    int expected = kFreeSlot;
    if (!r.state.compare_exchange_strong(expected, kFillingSlot, std::memory_order_acq_rel)) {
      continue;
    }
    std::memcpy(r.path, path.c_str(), path.size() + 1);
    r.state.store(kind == kDirectory ? kDirectorySlot : kFileSlot, std::memory_order_release);
    slot_ = static_cast<int>(i);
    return;
  }
}

RemovedOnSignal::~RemovedOnSignal() {
  if (slot_ >= 0) {
    registered_paths[static_cast<std::size_t>(slot_)].state.store(kFreeSlot,
                                                                  std::memory_order_release);
  }
}

void RemoveTemporaryFilesOnSignals() {
  for (int s : kCleanedSignals) {
    struct sigaction current {};
    if (sigaction(s, nullptr, &current) != 0 || current.sa_handler == SIG_IGN) continue;
    struct sigaction action {};
    action.sa_handler = RemoveRegisteredAndRaise;
    sigemptyset(&action.sa_mask);
    for (int other : kCleanedSignals) sigaddset(&action.sa_mask, other);
    action.sa_flags = SA_RESETHAND;
    sigaction(s, &action, nullptr);
  }
}

}  // namespace hybrid::cli
