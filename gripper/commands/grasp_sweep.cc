#include "gripper/commands/grasp_sweep.h"

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "commands/argument_message.h"
#include "hybrid/diagnosis/parallel_for.h"
#include "hybrid/gripper/geometric_finger.h"
#include "hybrid/gripper/hand.h"

namespace hybrid::cli {
namespace {

using gripper::Obstacle;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Rows are computed in blocks of this many (one ParallelFor index each).
constexpr int kBlock = 64;

// Throws OptionError unless the sweep's size and every offset are acceptable.
void CheckOffsets(std::span<const std::array<double, 2>> offsets, int threads) {
  if (offsets.size() > kMaxSweepRows) {
    throw OptionError("offsets", Arg("offsets") + ": at most " + std::to_string(kMaxSweepRows) +
                                     " rows (got " + std::to_string(offsets.size()) + ")");
  }
  for (size_t r = 0; r < offsets.size(); ++r) {
    if (!std::isfinite(offsets[r][0]) || !std::isfinite(offsets[r][1])) {
      throw OptionError("offsets",
                        Arg("offsets") + ": row " + std::to_string(r) + " is not finite");
    }
  }
  if (threads < 1 || threads > 64) {
    throw OptionError("threads",
                      Arg("threads") + " must be in 1..64 (got " + std::to_string(threads) + ")");
  }
}

// The objects moved by `offset`.
std::vector<Obstacle> Moved(const std::vector<Obstacle>& objects,
                            const std::array<double, 2>& offset) {
  const Eigen::Vector2d d(offset[0], offset[1]);
  std::vector<Obstacle> out;
  out.reserve(objects.size());
  for (const Obstacle& o : objects) {
    out.push_back(o.is_circle() ? Obstacle::Circle(o.a() + d, o.radius())
                                : Obstacle::Bar(o.a() + d, o.b() + d, o.radius()));
  }
  return out;
}

// The sweep's arrays sized for `rows` rows of `fingers` fingers, every row "invalid" until set.
GraspSweep Sized(size_t rows, int fingers) {
  GraspSweep s;
  s.fingers = fingers;
  const size_t per = rows * fingers;
  s.status.assign(rows, "invalid");
  s.message.assign(rows, "");
  s.first_contact.assign(rows, kNaN);
  s.motor.assign(per, kNaN);
  s.theta.assign(3 * per, kNaN);
  s.phase.assign(per, "");
  s.mode.assign(per, "");
  s.contact_g.assign(3 * per, kNaN);
  s.contact_by.assign(3 * per, "");
  s.stop.assign(per, kNaN);
  return s;
}

// Row r, finger f of `s` from `finger`.
void Store(GraspSweep& s, size_t r, int f, const HandFinger& finger) {
  const size_t at = r * s.fingers + f;
  s.motor[at] = finger.configuration.motor;
  for (int k = 0; k < 3; ++k) s.theta[3 * at + k] = finger.configuration.theta[k];
  s.phase[at] = gripper::PhaseName(finger.configuration.phase);
  s.mode[at] = gripper::FingerModeName(finger.configuration);
  for (const auto& c : finger.contacts) {
    s.contact_g[3 * at + c.link - 1] = c.g;
    s.contact_by[3 * at + c.link - 1] = c.by;
  }
  s.stop[at] = finger.stop;
}

// Runs row(r) for every row on `threads` threads; row throws std::invalid_argument for an invalid
// row, whose message is kept.
template <class Row>
void ForEachRow(GraspSweep& s, size_t rows, int threads, const Row& row) {
  const int blocks = static_cast<int>((rows + kBlock - 1) / kBlock);
  ParallelFor(blocks, threads, [&](int b) {
    for (size_t r = static_cast<size_t>(b) * kBlock; r < std::min(rows, (b + 1) * size_t{kBlock});
         ++r) {
      try {
        row(r);
      } catch (const std::invalid_argument& e) {
        s.status[r] = "invalid";
        s.message[r] = e.what();
      }
    }
  });
}

}  // namespace

GraspSweep HandSweep(const HandArgs& args, std::span<const std::array<double, 2>> offsets,
                     int threads) {
  CheckOffsets(offsets, threads);
  // The checks of one report, on the objects as given (they also parse them).
  HandArgs settings = args;
  settings.simulate = false;
  settings.draw.clear();
  const HandSettings hand_settings = CheckedHandSettings(settings);
  GraspSweep s = Sized(offsets.size(), 3);
  ForEachRow(s, offsets.size(), threads, [&](size_t r) {
    const gripper::Hand hand(Moved(hand_settings.objects, offsets[r]), hand_settings.spread,
                             hand_settings.commands);
    const HandOutcome outcome = HandOutcomeOf(hand, hand_settings.spread);
    s.status[r] = outcome.status;
    s.first_contact[r] = outcome.first_contact;
    for (int f = 0; f < 3; ++f) Store(s, r, f, HandFingerOf(hand, f));
  });
  return s;
}

GraspSweep FingerSweep(const std::vector<std::string>& objects, double g,
                       std::span<const std::array<double, 2>> offsets, int threads) {
  CheckOffsets(offsets, threads);
  CheckMotorPosition("g", g);
  const std::vector<Obstacle> parsed = ParseObjectList(objects);
  if (parsed.empty()) throw OptionError("objects", Arg("objects") + ": give at least one object");
  GraspSweep s = Sized(offsets.size(), 1);
  ForEachRow(s, offsets.size(), threads, [&](size_t r) {
    const gripper::GeometricFinger finger(Moved(parsed, offsets[r]));
    const double first = FirstObjectContact(finger);
    s.status[r] = ContactStatus(first, g);
    s.first_contact[r] = first;
    Store(s, r, 0, FingerAt(finger, g));
  });
  return s;
}

}  // namespace hybrid::cli
