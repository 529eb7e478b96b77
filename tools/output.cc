#include "tools/output.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>

namespace hybrid::cli {

void WriteOutput(const std::string& path, const std::string& text) {
  if (path.empty() || path == "-") {
    std::cout << text;
    std::cout.flush();
    if (!std::cout) throw OutputError("cannot write to standard output");
    return;
  }
  const std::filesystem::path target(path);
  std::error_code status_error;
  const auto status = std::filesystem::status(target, status_error);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    // A device or pipe (/dev/stdout, a FIFO): write into it; renaming over it would replace it.
    std::ofstream out(target, std::ios::binary);
    out << text;
    out.flush();
    if (!out) throw OutputError("cannot write '" + path + "'");
    return;
  }
  const std::filesystem::path temp =
      target.string() + ".tmp." + std::to_string(static_cast<long>(::getpid()));
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw OutputError("cannot write '" + path + "'");
    out << text;
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temp, ignored);
      throw OutputError("cannot write '" + path + "'");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temp, target, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    throw OutputError("cannot write '" + path + "'");
  }
}

void WriteOutputs(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::filesystem::path> temps;
  auto discard = [&]() {
    std::error_code ignored;
    for (const auto& t : temps) std::filesystem::remove(t, ignored);
  };
  for (const auto& [path, text] : files) {
    std::error_code status_error;
    const auto status = std::filesystem::status(path, status_error);
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
      discard();  // renaming over a directory or a device would fail or replace it
      throw OutputError("cannot write '" + path + "': not a regular file");
    }
    const std::filesystem::path temp =
        path + ".tmp." + std::to_string(static_cast<long>(::getpid()));
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (out) temps.push_back(temp);
    out << text;
    out.close();
    if (!out || path.empty() || path == "-") {
      discard();
      throw OutputError("cannot write '" + path + "'");
    }
  }
  for (size_t k = 0; k < files.size(); ++k) {
    std::error_code ec;
    std::filesystem::rename(temps[k], files[k].first, ec);
    if (ec) {
      discard();
      throw OutputError("cannot write '" + files[k].first + "'");
    }
  }
}

}  // namespace hybrid::cli
