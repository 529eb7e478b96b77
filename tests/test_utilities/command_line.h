#pragma once

// Shared helpers for tests that write files and run the `hybrid` binary (HYBRID_BINARY).
// RunHybrid and RunHybridJson exist only in the tests that tests/CMakeLists.txt lists in
// HYBRID_PROGRAM_TESTS: those are built after the program and given its path; elsewhere a call
// is a compile error saying so.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hybrid::testing {

/// `s` single-quoted for the shell.
inline std::string Quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// The whole content of a file ("" if it cannot be read).
inline std::string ReadAll(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// A fresh directory under the system temporary directory, removed by the destructor.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("hybrid_test_" + std::to_string(rd()) + "_" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// Writes `text` to the file `name` in the directory and returns its path.
  std::filesystem::path Write(const std::string& name, const std::string& text) const {
    const std::filesystem::path p = path_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  /// The path of `name` in the directory (not created).
  std::string File(const std::string& name) const { return (path_ / name).string(); }
  /// Names of the files in the directory, sorted.
  std::vector<std::string> Files() const {
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::directory_iterator(path_)) {
      out.push_back(e.path().filename());
    }
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  std::filesystem::path path_;
};

/// Whether this program is built with AddressSanitizer (which cannot run under a limit on
/// virtual memory: it reserves terabytes of address space for its shadow memory).
inline constexpr bool kAddressSanitizer =
#if defined(__SANITIZE_ADDRESS__)
    true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
    true;
#else
    false;
#endif
#else
    false;
#endif

/// Exit code and captured output of one run.
struct Result {
  int exit_code = -1;
  std::string out;
  std::string err;
};

#ifdef HYBRID_BINARY
/// Runs `hybrid ARGS` through the shell (arguments as written: quote them), with standard output
/// redirected to `stdout_target` when given. A run that does not exit normally is a test failure.
/// `shell_prefix` (e.g. "ulimit -v 100000; ") runs before the command in the same shell.
inline Result RunHybrid(const std::string& args, const std::string& stdout_target = "",
                        const std::string& shell_prefix = "") {
  TempDir dir;
  const std::filesystem::path out = dir.path() / "stdout", err = dir.path() / "stderr";
  const std::string command = shell_prefix + Quote(HYBRID_BINARY) + " " + args + " >" +
                              (stdout_target.empty() ? Quote(out.string()) : stdout_target) +
                              " 2>" + Quote(err.string()) + " </dev/null";
  const int status = std::system(command.c_str());
  Result r;
  if (WIFEXITED(status)) {
    r.exit_code = WEXITSTATUS(status);
  } else {
    ADD_FAILURE() << command << ": did not exit normally (status " << status << ")";
  }
  r.out = ReadAll(out);
  r.err = ReadAll(err);
  return r;
}

#else
/// Without HYBRID_BINARY (a test not in HYBRID_PROGRAM_TESTS), calling these fails to compile.
template <typename... Args>
inline constexpr bool kRunsTheProgram = false;
#define HYBRID_NOT_A_PROGRAM_TEST                                                       \
  static_assert(kRunsTheProgram<Args...>,                                               \
                "this test runs the hybrid program: add it to HYBRID_PROGRAM_TESTS in " \
                "tests/CMakeLists.txt (built after `hybrid`, given HYBRID_BINARY)")
template <typename... Args>
Result RunHybrid(const Args&...) {
  HYBRID_NOT_A_PROGRAM_TEST;
  return {};
}
template <typename... Args>
nlohmann::json RunHybridJson(const Args&...) {
  HYBRID_NOT_A_PROGRAM_TEST;
  return {};
}
#undef HYBRID_NOT_A_PROGRAM_TEST
#endif

/// The value of `key` in the JSON object `j`. Throws std::out_of_range with a message naming the
/// key and the keys there are when `j` is not an object or has no such key, so that a test
/// fails clearly instead of reading a null that indexing would insert.
inline const nlohmann::json& Field(const nlohmann::json& j, const std::string& key) {
  if (!j.is_object()) {
    throw std::out_of_range("JSON: expected an object with key '" + key + "', got " +
                            std::string(j.type_name()) + ": " + j.dump().substr(0, 200));
  }
  const auto it = j.find(key);
  if (it == j.end()) {
    std::string keys;
    for (const auto& [k, v] : j.items()) keys += (keys.empty() ? "" : ", ") + k;
    throw std::out_of_range("JSON: no key '" + key + "' (keys: " + keys + ")");
  }
  return *it;
}

/// Element `index` of the JSON array `j`; throws std::out_of_range naming the index and the
/// size when `j` is not an array or is too short.
inline const nlohmann::json& Field(const nlohmann::json& j, std::size_t index) {
  if (!j.is_array() || index >= j.size()) {
    throw std::out_of_range("JSON: no element " + std::to_string(index) + " in " +
                            std::string(j.type_name()) + " of size " + std::to_string(j.size()));
  }
  return j[index];
}

/// Field(Field(j, k1), k2)...: the value at a path of keys and indices, e.g.
/// Field(report, "properties", 0, "verdict").
template <typename K1, typename K2, typename... Rest>
const nlohmann::json& Field(const nlohmann::json& j, const K1& k1, const K2& k2,
                            const Rest&... rest) {
  return Field(Field(j, k1), k2, rest...);
}

#ifdef HYBRID_BINARY
/// Runs `hybrid ARGS --json`, expects exit code `expected_exit`, and parses standard output (an
/// output that is not JSON is a test failure and gives an empty object).
inline nlohmann::json RunHybridJson(const std::string& args, int expected_exit = 0) {
  const Result r = RunHybrid(args + " --json");
  EXPECT_EQ(r.exit_code, expected_exit) << "hybrid " << args << "\n" << r.err;
  try {
    return nlohmann::json::parse(r.out);
  } catch (const nlohmann::json::exception& e) {
    ADD_FAILURE() << "hybrid " << args << ": not JSON (" << e.what() << "):\n" << r.out;
    return nlohmann::json::object();
  }
}
#endif

}  // namespace hybrid::testing
