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
  WriteOutputs({{path, text}});
}

void WriteOutputs(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::filesystem::path> temps;
  std::vector<std::pair<std::string, std::string>> renames;  // (temp, target)
  std::vector<const std::pair<std::string, std::string>*> direct;
  auto discard = [&]() {
    std::error_code ignored;
    for (const auto& t : temps) std::filesystem::remove(t, ignored);
  };
  for (const auto& file : files) {
    const auto& [path, text] = file;
    std::error_code status_error;
    const auto status = std::filesystem::status(path, status_error);
    if (path.empty() || path == "-" ||
        (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))) {
      direct.push_back(&file);  // standard output, a device, a pipe, or a directory (fails)
      continue;
    }
    const std::string temp = path + ".tmp." + std::to_string(static_cast<long>(::getpid()));
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (out) temps.push_back(temp);
    out << text;
    out.close();
    if (!out) {
      discard();
      throw OutputError("cannot write '" + path + "'");
    }
    renames.emplace_back(temp, path);
  }
  try {
    for (const auto* file : direct) WriteOutput(file->first, file->second);
  } catch (const OutputError&) {
    discard();
    throw;
  }
  for (const auto& [temp, target] : renames) {
    std::error_code ec;
    std::filesystem::rename(temp, target, ec);
    if (ec) {
      discard();
      throw OutputError("cannot write '" + target + "'");
    }
  }
}

}  // namespace hybrid::cli
