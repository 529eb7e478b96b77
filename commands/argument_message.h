#pragma once

// The commands speak the words of the model and of their API, never those of one front end: a
// message that refers to an argument of a command ("until", "method", "group_by") holds a
// reference to it, which each front end renders its own way: the program as its flag
// ("--until", cli/flag_names.h), the Python module as the keyword argument ("until").

#include <functional>
#include <string>
#include <vector>

namespace hybrid::cli {

/// Text that may refer to arguments of a command by their API names: snake_case, the fields of
/// the commands' option structs and the keyword arguments of the Python module ("until",
/// "method", "group_by", "parameters", "objects", "out_model"). Built with `+` from text and Arg:
/// `Arg("until") + ": the horizon must be positive and finite"`. Literal text is kept as it is
/// (no character is special), so text from the user needs no escaping.
class ArgumentMessage {
 public:
  ArgumentMessage() = default;
  /// Literal text.
  ArgumentMessage(std::string text);  // NOLINT(google-explicit-constructor): text is a message
  ArgumentMessage(const char* text);  // NOLINT(google-explicit-constructor)

  /// A reference to the argument `name` (its API name).
  static ArgumentMessage Argument(std::string name);

  /// The text, each reference replaced by `name_of(API name)`.
  std::string Render(const std::function<std::string(const std::string&)>& name_of) const;

  /// The text in the API's words: each reference as its API name ("until: the horizon must be
  /// positive and finite").
  std::string Text() const;

  /// The API names referred to, in order of appearance (repeats included).
  std::vector<std::string> Arguments() const;

  /// Whether the message has neither text nor references.
  bool empty() const { return pieces_.empty(); }

  ArgumentMessage& operator+=(const ArgumentMessage& more);
  friend ArgumentMessage operator+(ArgumentMessage a, const ArgumentMessage& b) {
    a += b;
    return a;
  }
  friend bool operator==(const ArgumentMessage& a, const ArgumentMessage& b) {
    return a.pieces_ == b.pieces_;
  }

 private:
  // Literal text, or a reference to an argument (text: its API name). Adjacent literal pieces
  // are joined, and no piece is empty, so equal messages have equal pieces.
  struct Piece {
    std::string text;
    bool argument = false;
    bool operator==(const Piece&) const = default;
  };
  std::vector<Piece> pieces_;
};

/// A reference to the argument `name` (API name) in a message: ArgumentMessage::Argument(name).
ArgumentMessage Arg(std::string name);

}  // namespace hybrid::cli
