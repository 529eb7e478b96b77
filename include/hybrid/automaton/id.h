#pragma once

#include <compare>
#include <cstddef>
#include <functional>

namespace hybrid {

/// A typed index (mode, transition, ...) so that ids of different kinds cannot be mixed up.
/// Ids are assigned densely from 0 in insertion order by the owning Automaton.
template <class Tag>
class Id {
 public:
  constexpr Id() = default;
  constexpr explicit Id(int value) : value_(value) {}
  constexpr int value() const { return value_; }
  constexpr bool is_valid() const { return value_ >= 0; }
  friend constexpr auto operator<=>(Id, Id) = default;

 private:
  int value_ = -1;
};

struct ModeTag;
struct TransitionTag;
/// Index of a mode within its Automaton.
using ModeId = Id<ModeTag>;
/// Index of a transition within its Automaton.
using TransitionId = Id<TransitionTag>;

}  // namespace hybrid

template <class Tag>
struct std::hash<hybrid::Id<Tag>> {
  std::size_t operator()(hybrid::Id<Tag> id) const noexcept { return std::hash<int>()(id.value()); }
};
