#pragma once

// Walks of expression and predicate trees without recursion (private to automaton/). Trees may be
// up to kMaxTreeDepth deep; their walks keep their pending work on the heap, so that none of them
// depends on the size of the caller's stack or on the stack frames a compiler or sanitizer makes.

#include <cstddef>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace hybrid::internal {

/// The value of `root` computed bottom-up: `shortcut(node)` may give a node's value directly
/// (leaves, memoised nodes), otherwise its children (`children(node)`, a span) are valued first,
/// left to right, and `combine(node, child_values)` gives its value. Uses heap memory
/// proportional to the depth times the fan-out, and constant stack.
template <class T, class Tree, class Children, class Shortcut, class Combine>
T PostOrder(const Tree& root, Children children, Shortcut shortcut, Combine combine) {
  struct Frame {
    const Tree* node;
    std::size_t next;  // next child to value
  };
  std::vector<Frame> frames;
  std::vector<T> values;
  auto enter = [&](const Tree& node) {
    if (std::optional<T> value = shortcut(node)) {
      values.push_back(std::move(*value));
    } else {
      frames.push_back({&node, 0});
    }
  };
  enter(root);
  while (!frames.empty()) {
    Frame& top = frames.back();
    const auto kids = children(*top.node);
    if (top.next < kids.size()) {
      enter(kids[top.next++]);  // may reallocate `frames`: `top` is not used after this
      continue;
    }
    const Tree& node = *top.node;
    frames.pop_back();
    const std::size_t n = kids.size();
    T value = combine(node, std::span<T>(values.data() + (values.size() - n), n));
    values.erase(values.end() - static_cast<std::ptrdiff_t>(n), values.end());
    values.push_back(std::move(value));
  }
  return std::move(values.back());
}

/// Calls `visit(node)` on every node of the tree under `root`, parents before children and
/// children left to right (the order of a recursive pre-order walk), with constant stack.
template <class Tree, class Children, class Visit>
void PreOrder(const Tree& root, Children children, Visit visit) {
  std::vector<const Tree*> todo = {&root};
  while (!todo.empty()) {
    const Tree* node = todo.back();
    todo.pop_back();
    visit(*node);
    const auto kids = children(*node);
    for (std::size_t i = kids.size(); i-- > 0;) todo.push_back(&kids[i]);
  }
}

}  // namespace hybrid::internal
