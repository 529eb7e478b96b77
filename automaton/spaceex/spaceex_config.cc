#include "automaton/spaceex/spaceex_config.h"

#include <cctype>
#include <utility>

#include "hybrid/automaton/parser.h"

namespace hybrid::spaceex {
namespace {

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r'; }

}  // namespace

SpaceExConfig::SpaceExConfig(std::string_view text, std::string file)
    : file_(std::move(file)), positions_(text) {
  auto fail = [&](std::size_t offset, const std::string& message) {
    const auto [line, column] = positions_.LineColumn(offset);
    throw ParseError(file_, line, column, message);
  };
  std::size_t pos = 0;
  while (pos < text.size()) {
    while (pos < text.size() && (IsSpace(text[pos]) || text[pos] == '\n')) ++pos;
    if (pos >= text.size()) break;
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    if (text[pos] == '#' || text.substr(pos, 2) == "//") {
      pos = end;
      continue;
    }
    const std::size_t key_start = pos;
    while (pos < end && (std::isalnum(static_cast<unsigned char>(text[pos])) || text[pos] == '-' ||
                         text[pos] == '_')) {
      ++pos;
    }
    const std::string key(text.substr(key_start, pos - key_start));
    while (pos < end && IsSpace(text[pos])) ++pos;
    if (key.empty() || pos >= end || text[pos] != '=') {
      fail(pos, "expected 'option = value'");
    }
    ++pos;
    while (pos < end && IsSpace(text[pos])) ++pos;
    Value value;
    if (pos < text.size() && text[pos] == '"') {
      const std::size_t close = text.find('"', pos + 1);
      if (close == std::string_view::npos) fail(pos, "unterminated '\"'");
      value = {std::string(text.substr(pos + 1, close - pos - 1)), pos + 1};
      pos = close + 1;
      end = text.find('\n', pos);
      if (end == std::string_view::npos) end = text.size();
      std::size_t rest = pos;
      while (rest < end && IsSpace(text[rest])) ++rest;
      if (rest < end) fail(rest, "unexpected text after the closing '\"'");
    } else {
      std::size_t last = end;
      while (last > pos && IsSpace(text[last - 1])) --last;
      value = {std::string(text.substr(pos, last - pos)), pos};
    }
    if (!options_.emplace(key, std::move(value)).second) {
      fail(key_start, "option '" + key + "' is given twice");
    }
    pos = end;
  }
}

std::optional<SpaceExConfig::Value> SpaceExConfig::Find(const std::string& option) const {
  const auto it = options_.find(option);
  if (it == options_.end()) return std::nullopt;
  return it->second;
}

}  // namespace hybrid::spaceex
