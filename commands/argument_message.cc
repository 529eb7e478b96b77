#include "commands/argument_message.h"

#include <utility>

namespace hybrid::cli {

ArgumentMessage::ArgumentMessage(std::string text) {
  if (!text.empty()) pieces_.push_back({std::move(text), false});
}

ArgumentMessage::ArgumentMessage(const char* text) : ArgumentMessage(std::string(text)) {}

ArgumentMessage ArgumentMessage::Argument(std::string name) {
  ArgumentMessage m;
  m.pieces_.push_back({std::move(name), true});
  return m;
}

std::string ArgumentMessage::Render(
    const std::function<std::string(const std::string&)>& name_of) const {
  std::string out;
  for (const Piece& p : pieces_) out += p.argument ? name_of(p.text) : p.text;
  return out;
}

std::string ArgumentMessage::Text() const {
  return Render([](const std::string& name) { return name; });
}

std::vector<std::string> ArgumentMessage::Arguments() const {
  std::vector<std::string> out;
  for (const Piece& p : pieces_) {
    if (p.argument) out.push_back(p.text);
  }
  return out;
}

ArgumentMessage& ArgumentMessage::operator+=(const ArgumentMessage& more) {
  for (const Piece& p : more.pieces_) {
    if (!p.argument && !pieces_.empty() && !pieces_.back().argument) {
      pieces_.back().text += p.text;
    } else {
      pieces_.push_back(p);
    }
  }
  return *this;
}

ArgumentMessage Arg(std::string name) { return ArgumentMessage::Argument(std::move(name)); }

}  // namespace hybrid::cli
