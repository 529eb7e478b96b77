#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "automaton/spaceex/text_positions.h"

namespace hybrid::spaceex {

/// The text of an element (a flow, a guard, a map's value) with where it starts in the file.
struct SxText {
  std::string value;       ///< as parsed: entities replaced, line ends normalised
  std::size_t offset = 0;  ///< byte offset of its first character in the file
  bool cdata = false;      ///< written as <![CDATA[...]]> (no entities)
};

/// A `<param>` of a component: a real variable (`dynamics="any"`), a constant
/// (`dynamics="const"`) or a synchronisation label (`type="label"`).
struct SxParam {
  enum class Type { kVariable, kConstant, kLabel };
  std::string name;
  Type type = Type::kVariable;
  bool local = false;
  std::size_t offset = 0;
};

struct SxLocation {
  std::string id;
  std::string name;
  std::size_t offset = 0;
  std::optional<SxText> invariant;
  std::optional<SxText> flow;
};

struct SxTransition {
  std::string source;  ///< location id
  std::string target;
  std::size_t offset = 0;
  std::optional<SxText> label;
  std::optional<SxText> guard;
  std::optional<SxText> assignment;
  bool asap = false;  ///< `asap="true"` (or "1", any case): taken as soon as the guard holds
};

struct SxMap {
  std::string key;
  SxText value;
  std::size_t offset = 0;
};

/// A `<bind>` of a network component: an instance `as` of component `component`.
struct SxBind {
  std::string component;
  std::string as;
  std::size_t offset = 0;
  std::vector<SxMap> maps;
};

/// A `<component>`: a base component (locations, transitions) or a network (binds).
struct SxComponent {
  std::string id;
  std::size_t offset = 0;
  std::vector<SxParam> params;
  std::vector<SxLocation> locations;
  std::vector<SxTransition> transitions;
  std::vector<SxBind> binds;

  bool IsNetwork() const { return !binds.empty(); }
  const SxParam* FindParam(std::string_view name) const;
  const SxLocation* FindLocation(std::string_view id) const;
};

/// A SpaceEx model file (the SX format: `<sspaceex>` with `<component>`s) read into components,
/// every element and text with its position in the file for messages.
class SpaceExDocument {
 public:
  /// Parses `xml` (named `file` in messages) with pugixml. Throws ParseError at the line and
  /// column of malformed XML, a root that is not `<sspaceex>`, a missing or malformed required
  /// attribute, an element the import does not support (named in the message), an attribute
  /// not among those SpaceEx gives the element (layout attributes such as x, y, width, height
  /// and bezier are known; `<note>`, `<labelposition>` and `<middlepoint>` are not read), a
  /// boolean attribute (`asap`, `local`, `controlled`) other than true, false, 1 or 0 in any
  /// case, `controlled="false"`, or a duplicate component, parameter or location id.
  SpaceExDocument(std::string_view xml, std::string file);

  const std::string& file() const { return file_; }
  const std::vector<SxComponent>& components() const { return components_; }
  const SxComponent* Find(std::string_view id) const;
  /// Line and column of byte `offset` of the file.
  std::pair<int, int> LineColumn(std::size_t offset) const { return positions_.LineColumn(offset); }
  /// The byte offset in the file of character `index` of `text`'s value (entities and CRLF
  /// line ends count as the one character they stand for).
  std::size_t OffsetOf(const SxText& text, std::size_t index) const;
  /// Throws ParseError at byte `offset` of the file.
  [[noreturn]] void Fail(std::size_t offset, const std::string& message) const;

 private:
  std::string raw_;
  std::string file_;
  TextPositions positions_;
  std::vector<SxComponent> components_;
};

}  // namespace hybrid::spaceex
