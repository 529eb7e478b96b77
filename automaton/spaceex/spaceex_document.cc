#include "automaton/spaceex/spaceex_document.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <pugixml.hpp>
#include <set>
#include <utility>

#include "hybrid/automaton/parser.h"

namespace hybrid::spaceex {
namespace {

// Reads the elements of one document; `doc` reports errors at raw offsets.
class Reader {
 public:
  Reader(const SpaceExDocument& doc, std::string_view raw) : doc_(doc), raw_(raw) {}

  // Offset of an element's '<'.
  std::size_t At(const pugi::xml_node& node) const {
    const auto offset = static_cast<std::size_t>(std::max<std::ptrdiff_t>(node.offset_debug(), 0));
    return offset > 0 && raw_[offset - 1] == '<' ? offset - 1 : offset;
  }
  // Offsets of attribute `name` in the start tag of `node`: of its name and of its value's first
  // character; both the element's when it cannot be found.
  std::pair<std::size_t, std::size_t> AttributePlace(const pugi::xml_node& node,
                                                     const char* name) const {
    const std::size_t start = At(node);
    const std::size_t end = raw_.find('>', start);
    std::size_t pos = start;
    while ((pos = raw_.find(name, pos + 1)) != std::string_view::npos && pos < end) {
      const char before = raw_[pos - 1];
      std::size_t q = pos + std::strlen(name);
      while (q < end && (raw_[q] == ' ' || raw_[q] == '\t' || raw_[q] == '\n' || raw_[q] == '\r'))
        ++q;
      if ((before == ' ' || before == '\t' || before == '\n' || before == '\r') && q < end &&
          raw_[q] == '=') {
        const std::size_t value = raw_.find_first_of("\"'", q);
        return {pos, value < end ? value + 1 : pos};
      }
    }
    return {start, start};
  }
  // Offset of attribute `name`'s value in the start tag of `node` (or of the element).
  std::size_t AttributeAt(const pugi::xml_node& node, const char* name) const {
    return AttributePlace(node, name).second;
  }

  // Fails at the first attribute of `node` that is not in `known`: SpaceEx gives every
  // attribute of these elements a meaning or a place in the editor's drawing, so an attribute the
  // import does not know could change the model unseen. Names starting with `prefix` (when
  // given) are accepted too.
  void OnlyAttributes(const pugi::xml_node& node, std::initializer_list<const char*> known,
                      const char* prefix = nullptr) const {
    for (const pugi::xml_attribute a : node.attributes()) {
      bool ok = prefix != nullptr && std::strncmp(a.name(), prefix, std::strlen(prefix)) == 0;
      for (const char* k : known) ok = ok || std::strcmp(a.name(), k) == 0;
      if (ok) continue;
      std::string list;
      for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      doc_.Fail(AttributePlace(node, a.name()).first,
                std::string("unknown attribute '") + a.name() + "' of <" + node.name() + ">" +
                    (list.empty() ? " (it takes none)" : " (known: " + list + ")"));
    }
  }

  // The boolean attribute `name` of `node`: true or false, also written 1 or 0, in any case;
  // `absent` when it is not given. Fails at the value otherwise.
  bool Boolean(const pugi::xml_node& node, const char* name, bool absent) const {
    const pugi::xml_attribute a = node.attribute(name);
    if (!a) return absent;
    std::string value = a.value();
    for (char& c : value) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (value == "true" || value == "1") return true;
    if (value == "false" || value == "0") return false;
    doc_.Fail(AttributeAt(node, name), std::string("attribute '") + name + "' of <" + node.name() +
                                           "> must be true or false (or 1 or 0), not '" +
                                           a.value() + "'");
  }

  std::string Required(const pugi::xml_node& node, const char* name) const {
    const pugi::xml_attribute a = node.attribute(name);
    if (!a)
      doc_.Fail(At(node), std::string("<") + node.name() + "> needs the attribute '" + name + "'");
    if (*a.value() == '\0')
      doc_.Fail(AttributeAt(node, name), std::string("'") + name + "' is empty");
    return a.value();
  }

  // The text of element `node` (its first PCDATA or CDATA child); empty text at the element
  // when it has none.
  SxText Text(const pugi::xml_node& node) const {
    for (const pugi::xml_node child : node.children()) {
      if (child.type() == pugi::node_pcdata || child.type() == pugi::node_cdata) {
        return {child.value(), static_cast<std::size_t>(child.offset_debug()),
                child.type() == pugi::node_cdata};
      }
      if (child.type() == pugi::node_element) {
        doc_.Fail(At(child), std::string("unexpected element <") + child.name() + "> in <" +
                                 node.name() + ">");
      }
    }
    return {"", At(node), false};
  }
  // Text(node) of an element that takes no attributes (a flow, a guard, ...).
  SxText Content(const pugi::xml_node& node) const {
    OnlyAttributes(node, {});
    return Text(node);
  }

  // Fails on any child element of `node` but those named in `known` (and notes).
  void OnlyChildren(const pugi::xml_node& node, std::initializer_list<const char*> known) const {
    for (const pugi::xml_node child : node.children()) {
      if (child.type() != pugi::node_element) continue;
      bool ok = std::strcmp(child.name(), "note") == 0;
      for (const char* k : known) ok = ok || std::strcmp(child.name(), k) == 0;
      if (!ok) {
        doc_.Fail(At(child), std::string("unsupported element <") + child.name() + "> in <" +
                                 node.name() + ">");
      }
    }
  }

  SxParam Param(const pugi::xml_node& node) const {
    OnlyAttributes(node, {"name", "type", "local", "d1", "d2", "dynamics", "controlled"});
    SxParam p;
    p.name = Required(node, "name");
    p.offset = At(node);
    const std::string type = Required(node, "type");
    p.local = Boolean(node, "local", false);
    // An uncontrolled variable may change arbitrarily at the component's jumps: not supported.
    if (!Boolean(node, "controlled", true)) {
      doc_.Fail(AttributeAt(node, "controlled"),
                "controlled=\"false\" is not supported: parameters are controlled by their "
                "component");
    }
    if (type == "label") {
      p.type = SxParam::Type::kLabel;
      return p;
    }
    if (type != "real") {
      doc_.Fail(AttributeAt(node, "type"),
                "parameter type '" + type + "' is not supported (only 'real' and 'label')");
    }
    for (const char* d : {"d1", "d2"}) {
      const pugi::xml_attribute a = node.attribute(d);
      if (a && std::strcmp(a.value(), "1") != 0) {
        doc_.Fail(AttributeAt(node, d),
                  "matrix parameters are not supported (" + std::string(d) + " must be 1)");
      }
    }
    const std::string dynamics = node.attribute("dynamics").as_string("any");
    if (dynamics == "const") {
      p.type = SxParam::Type::kConstant;
    } else if (dynamics != "any") {
      doc_.Fail(AttributeAt(node, "dynamics"),
                "dynamics '" + dynamics + "' is not supported (only 'any' and 'const')");
    }
    return p;
  }

  SxLocation Location(const pugi::xml_node& node) const {
    OnlyChildren(node, {"invariant", "flow"});
    OnlyAttributes(node, {"id", "name", "x", "y", "width", "height"});
    SxLocation l;
    l.id = Required(node, "id");
    l.name = node.attribute("name").as_string(l.id.c_str());
    l.offset = At(node);
    if (const pugi::xml_node inv = node.child("invariant")) l.invariant = Content(inv);
    if (const pugi::xml_node flow = node.child("flow")) l.flow = Content(flow);
    return l;
  }

  SxTransition Transition(const pugi::xml_node& node) const {
    OnlyChildren(node, {"label", "guard", "assignment", "labelposition", "middlepoint"});
    OnlyAttributes(node, {"source", "target", "asap", "timedriven", "priority", "bezier"});
    for (const char* unsupported : {"timedriven", "priority"}) {
      if (node.attribute(unsupported)) {
        doc_.Fail(AttributeAt(node, unsupported),
                  std::string("transition attribute '") + unsupported + "' is not supported");
      }
    }
    SxTransition t;
    t.source = Required(node, "source");
    t.target = Required(node, "target");
    t.offset = At(node);
    t.asap = Boolean(node, "asap", false);
    if (const pugi::xml_node n = node.child("label")) t.label = Content(n);
    if (const pugi::xml_node n = node.child("guard")) t.guard = Content(n);
    if (const pugi::xml_node n = node.child("assignment")) t.assignment = Content(n);
    return t;
  }

  SxBind Bind(const pugi::xml_node& node) const {
    OnlyChildren(node, {"map"});
    OnlyAttributes(node, {"component", "as", "x", "y", "width", "height"});
    SxBind b;
    b.component = Required(node, "component");
    b.as = Required(node, "as");
    b.offset = At(node);
    std::set<std::string> keys;
    for (const pugi::xml_node m : node.children("map")) {
      OnlyAttributes(m, {"key"});
      SxMap map{Required(m, "key"), Text(m), At(m)};
      if (!keys.insert(map.key).second) {
        doc_.Fail(AttributeAt(m, "key"), "'" + map.key + "' is mapped twice");
      }
      b.maps.push_back(std::move(map));
    }
    return b;
  }

  SxComponent Component(const pugi::xml_node& node) const {
    OnlyChildren(node, {"param", "location", "transition", "bind"});
    OnlyAttributes(node, {"id"});
    SxComponent c;
    c.id = Required(node, "id");
    c.offset = At(node);
    for (const pugi::xml_node p : node.children("param")) {
      c.params.push_back(Param(p));
      if (c.FindParam(c.params.back().name) != &c.params.back()) {
        doc_.Fail(AttributeAt(p, "name"), "duplicate parameter '" + c.params.back().name + "'");
      }
    }
    for (const pugi::xml_node l : node.children("location")) {
      c.locations.push_back(Location(l));
      if (c.FindLocation(c.locations.back().id) != &c.locations.back()) {
        doc_.Fail(AttributeAt(l, "id"), "duplicate location id '" + c.locations.back().id + "'");
      }
    }
    for (const pugi::xml_node t : node.children("transition"))
      c.transitions.push_back(Transition(t));
    for (const pugi::xml_node b : node.children("bind")) c.binds.push_back(Bind(b));
    if (c.IsNetwork() && !(c.locations.empty() && c.transitions.empty())) {
      doc_.Fail(c.offset, "component '" + c.id + "' has both binds and locations");
    }
    return c;
  }

 private:
  const SpaceExDocument& doc_;
  std::string_view raw_;
};

}  // namespace

const SxParam* SxComponent::FindParam(std::string_view name) const {
  for (const SxParam& p : params) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

const SxLocation* SxComponent::FindLocation(std::string_view id) const {
  for (const SxLocation& l : locations) {
    if (l.id == id) return &l;
  }
  return nullptr;
}

SpaceExDocument::SpaceExDocument(std::string_view xml, std::string file)
    : raw_(xml), file_(std::move(file)), positions_(raw_) {
  pugi::xml_document doc;
  // UTF-8 as is (no conversion of the ISO-8859-1 files SpaceEx writes), so that offsets are
  // those of the file; names must be ASCII anyway.
  const pugi::xml_parse_result result =
      doc.load_buffer(raw_.data(), raw_.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!result) {
    // pugixml may report the offset just past the end of a truncated document.
    const auto offset =
        std::min(static_cast<std::size_t>(std::max<std::ptrdiff_t>(result.offset, 0)), raw_.size());
    Fail(offset, std::string("malformed XML: ") + result.description());
  }
  const Reader reader(*this, raw_);
  const pugi::xml_node root = doc.document_element();
  if (std::strcmp(root.name(), "sspaceex") != 0) {
    Fail(reader.At(root), std::string("not a SpaceEx model: the root element is <") + root.name() +
                              ">, expected <sspaceex>");
  }
  reader.OnlyChildren(root, {"component"});
  reader.OnlyAttributes(root, {"xmlns", "version", "math"}, "xmlns:");
  for (const pugi::xml_node c : root.children("component")) {
    components_.push_back(reader.Component(c));
    if (Find(components_.back().id) != &components_.back()) {
      Fail(reader.AttributeAt(c, "id"), "duplicate component '" + components_.back().id + "'");
    }
  }
  if (components_.empty()) Fail(reader.At(root), "the model has no <component>");
}

const SxComponent* SpaceExDocument::Find(std::string_view id) const {
  for (const SxComponent& c : components_) {
    if (c.id == id) return &c;
  }
  return nullptr;
}

std::size_t SpaceExDocument::OffsetOf(const SxText& text, std::size_t index) const {
  std::size_t raw = text.offset;
  for (std::size_t i = 0; i < index && raw < raw_.size(); ++i) {
    if (!text.cdata && raw_[raw] == '&') {
      const std::size_t semi = raw_.find(';', raw);
      raw = semi == std::string::npos ? raw + 1 : semi + 1;
    } else if (raw_[raw] == '\r' && raw + 1 < raw_.size() && raw_[raw + 1] == '\n') {
      raw += 2;
    } else {
      ++raw;
    }
  }
  return raw;
}

void SpaceExDocument::Fail(std::size_t offset, const std::string& message) const {
  const auto [line, column] = positions_.LineColumn(offset);
  throw ParseError(file_, line, column, message);
}

}  // namespace hybrid::spaceex
