#!/usr/bin/env python3
"""Writes spec/finger.ha: one Robotiq 3-finger gripper finger as the hybrid automaton of section 3
of Franchi and Hauser's report (TR711).

The discrete states, flows and the six transition kinds are enumerated by the rules below rather
than typed by hand, so that every state tuple of the report's table and every transition between
them is covered uniformly. Run `python3 tools/generate_finger.py > spec/finger.ha` and
`python3 tools/generate_finger.py --driven > spec/driven_finger.ha` (the same finger with the motor
rate u set by the controller of spec/controller.ha, for spec/controlled_finger.ha); the test
`finger_spec_test` checks that the committed files equal this script's output.
Decisions where the report is silent or inconsistent are documented in docs/finger_model.md.
"""

import itertools
import sys

# (c, l) pairs of one link: free, blocked by contact, blocked by its upper limit.
LINK = [(0, 0), (1, 0), (0, 1)]


def phase(s):
    c1, c2, c3, l1, l2, l3 = s
    if c3 == 1 or l3 == 1 or is_palm(s):
        return "4"
    if c2 == 1 or l2 == 1:
        return "3"
    if c1 == 1 or l1 == 1:
        return "2'" if l3 == -1 else "2"
    return "1'" if l3 == -1 else "1"


def is_palm(s):
    """Free space fully closed: links 1 and 2 at their limits, link 3 at its lower limit. Table 4.1
    of the report: the finger stops at g = 240 by self-collision with the palm (decision D3)."""
    c1, c2, c3, l1, l2, l3 = s
    return l1 == 1 and l2 == 1 and l3 == -1 and not c1 and not c2 and not c3


def states():
    """The state tuples of the report's table (section 3), plus phase 4 with l3 = -1."""
    out = [(0, 0, 0, 0, 0, 0), (0, 0, 0, 0, 0, -1)]                 # phases 1, 1'
    out += [(1, 0, 0, 0, 0, 0), (0, 0, 0, 1, 0, 0)]                 # phase 2
    out += [(1, 0, 0, 0, 0, -1), (0, 0, 0, 1, 0, -1)]               # phase 2'
    for (c1, l1), (c2, l2) in itertools.product(LINK, [(1, 0), (0, 1)]):
        out.append((c1, c2, 0, l1, l2, 0))                          # phase 3
    for (c1, l1), (c2, l2) in itertools.product(LINK, LINK):
        out.append((c1, c2, 1, l1, l2, 0))                          # phase 4, link 3 in contact
    for (c1, l1), (c2, l2) in itertools.product(LINK, [(1, 0), (0, 1)]):
        out.append((c1, c2, 0, l1, l2, 1))                          # phase 4, link 3 at its limit
    for c1, l1 in LINK:
        out.append((c1, 0, 1, l1, 0, -1))                           # phase 4, contact at lower limit
    out.append((0, 0, 0, 1, 1, -1))                                 # phase 4, against the palm
    return out


def name(s):
    c1, c2, c3, l1, l2, l3 = s
    l = lambda v: "n" if v == -1 else str(v)
    return f"c{c1}{c2}{c3}_l{l(l1)}{l(l2)}{l(l3)}"


FLOWS = {
    "1": {"theta1": "m1 * u", "theta3": "-(m1 * u)", "g": "u"},
    "1'": {"theta1": "m1 * u", "g": "u"},
    "2": {"theta2": "m2 * u", "theta3": "-(m2 * u)", "g": "u"},
    "2'": {"theta2": "m2 * u", "g": "u"},
    "3": {"theta3": "m3 * u", "g": "u"},
    "4": {},
}

# Links whose position in space changes in each phase (an object can newly touch only these).
MOVING = {"1": {1, 2, 3}, "1'": {1, 2, 3}, "2": {2, 3}, "2'": {2, 3}, "3": {3}, "4": set()}


def normalise(s):
    """A link-2 block with l3 = -1 is not a state of the table: transition 6 (l3: -1 -> 0, guard
    theta3 + u > theta3_min) is enabled at once for u > 0, so the target is the l3 = 0 state."""
    c1, c2, c3, l1, l2, l3 = s
    if (c2 or l2) and l3 == -1 and not c3 and not is_palm(s):
        return (c1, c2, c3, l1, l2, 0)
    return s


# Phase 3 (decision C1, docs/finger_model.md): section 4's law theta3(g) = theta3_s +
# (theta3_max - theta3_s) (g - g_s) / (255 - g), continued from theta3_s and g_s, the values when
# link 2 was blocked, differentiated in g. (Section 3's m3(g) = theta3_min + c / (255 - g) is not
# this rate.) The max(.., 1e-12) only matters for g_s = g = 255, where the numerator is 0 too.
M3 = "m3_scale * (theta3_max - theta3_s) * (255 - g_s) / max((255 - g) ^ 2, 1e-12) * u"


def rate(flow):
    """A flow right-hand side as written in the model (m3 expanded)."""
    return M3 if flow == "m3 * u" else flow


def pushes(flow, direction):
    """The input condition under which `flow` moves its joint in `direction` (+1 up, -1 down).
    Every rate is a coefficient times u whose sign is known: m1, m2 > 0, and the phase-3
    coefficient (theta3_max - theta3_s)(255 - g_s)/(255 - g)^2 >= 0 because theta3_s <= 0 <
    theta3_max (see the property phase3_law). Writing `u > 0` rather than `RATE > 0` keeps every
    guard affine, which `hybrid check` needs to encode urgency exactly."""
    sign = -1 if flow.startswith("-") else 1
    return "u > 0" if sign * direction > 0 else "u < 0"


def release_guard(i):
    """Transitions 2 and 4 (D2): link i leaves its contact or limit when the motor reverses and
    link i + 1 is back where it was when link i stopped: theta2 at its minimum for link 1,
    theta3 at theta3_s for link 2 (C2), at once for link 3."""
    if i == 1:
        return "theta2 == theta2_min and u < 0"
    if i == 2:
        return "theta3 == theta3_s and u < 0"
    return "u < 0"


def stall_labels(out):
    """The driven finger: every transition into phase 4 from another phase is labelled `stall`,
    which spec/controller.ha's transitions into `stopped` share, so that the controller stops the
    motor exactly when the finger can move no further (the firmware's current limit)."""
    labelled = []
    for tname, s, t, guard, label, resets in out:
        if phase(t) == "4" and phase(s) != "4":
            label = "stall"
        labelled.append((tname, s, t, guard, label, resets))
    return labelled


def transitions(all_states):
    known = set(all_states)
    out = []
    for s in all_states:
        c = list(s[:3])
        l = list(s[3:])
        p = phase(s)
        flows = FLOWS[p]

        def emit(kind, link, target, guard, label, resets=""):
            target = normalise(tuple(target))
            if target not in known or target == s:
                return
            blocks_link2 = (target[1] or target[4]) and not (s[1] or s[4])
            if blocks_link2:
                # Remember where link 2 stopped: the start of the phase-3 law.
                extra = "theta3_s := theta3, g_s := g"
                resets = f"{resets}, {extra}" if resets else extra
            releases_link2 = (s[1] or s[4]) and not (target[1] or target[4])
            primed = target[:5] + (-1,)
            if releases_link2 and target[5] == 0 and (phase(target) in ("1", "2") or
                                                      primed in known):
                # Decision C2: back in phase 1 or 2 (or in phase 4 with link 3 in contact), link 3
                # is at its lower limit (the primed state) when it was there when link 2 stopped.
                # (`hybrid check` found the phase-4 case: without it, releasing link 2 from
                # c111_l000 left theta3 at its limit with l3 = 0, breaking distal_coupling.)
                # The primed twin comes first: at the crossing the simulator tests a guard in
                # its closure, where `theta3_s > theta3_min` holds for theta3_s = theta3_min
                # too; declaration order then gives the primed phase priority.
                out.append((f"t{kind}_{name(s)}_to_{name(primed)}", s, primed,
                            f"{guard} and theta3_s <= theta3_min", label, resets))
                out.append((f"t{kind}_{name(s)}_to_{name(target)}", s, target,
                            f"{guard} and theta3_s > theta3_min", label, resets))
                return
            out.append((f"t{kind}_{name(s)}_to_{name(target)}", s, target, guard, label, resets))

        for i in (1, 2, 3):
            ci, li = c[i - 1], l[i - 1]
            theta = f"theta{i}"
            # 1. c_i: 0 -> 1, an object is hit by link i (at motor position gob_i).
            #    Only while closing (u > 0): an opening finger moves away from the object.
            if ci == 0 and li != 1 and i in MOVING[p]:
                t = c + l
                t[i - 1] = 1
                emit(1, i, t, f"g >= gob{i} and u > 0", f"contact{i}")
            # 2. c_i: 1 -> 0 when theta_{i+1} = theta_{i+1,min} and u < 0 (link 3: u < 0).
            #    Link 2 (decision C2): theta3 back at theta3_s, where phase 3 started.
            if ci == 1:
                t = c + l
                t[i - 1] = 0
                emit(2, i, t, release_guard(i), f"release{i}")
            # 3. l_i: 0 -> 1 when theta_i + dtheta_i >= theta_i,max: in continuous time, theta_i
            #    at its limit and its rate pushing further (otherwise the finger moving away from
            #    the limit would be caught again at once).
            if li == 0 and ci == 0 and theta in flows:
                t = c + l
                t[3 + i - 1] = 1
                emit(3, i, t, f"{theta} >= {theta}_max and {pushes(flows[theta], +1)}", "",
                     f"{theta} := {theta}_max")
            # 4. l_i: 1 -> 0 when the motor reverses. Decision D2: like transition 2, links 1 and 2
            #    leave their limits only once the next link is back at its minimum
            #    (theta_{i+1} = theta_{i+1,min}), so that opening retraces table 4.1.
            if li == 1:
                t = c + l
                t[3 + i - 1] = 0
                emit(4, i, t, release_guard(i), "")
        # 5. l3: 0 -> -1 when theta3 reaches its lower limit (phases 1 and 2, where the table has a
        #    primed phase to go to).
        if l[2] == 0 and c[2] == 0 and "theta3" in flows and p in ("1", "2"):
            emit(5, 3, c + l[:2] + [-1],
                 f"theta3 <= theta3_min and {pushes(flows['theta3'], -1)}", "",
                 "theta3 := theta3_min")
        # 6. l3: -1 -> 0. Decision D1: when the motor reverses and the vertical-orientation
        #    coupling theta3 = -(theta1 + theta2) of phases 1 and 2 lifts theta3 off its limit,
        #    i.e. theta1 + theta2 <= -theta3_min. (The report's "theta3 + u > theta3_min" holds at
        #    once for u > 0 and would chatter between phases 1 and 1' at g = 110.)
        if l[2] == -1:
            emit(6, 3, c + l[:2] + [0], "theta1 + theta2 <= -theta3_min and u < 0", "")
    return out


DRIVEN_HEADER = """# One finger of the Robotiq 3-Finger Adaptive Gripper driven by its controller: spec/finger.ha's
# automaton (section 3 of Franchi and Hauser's report TR711) with the motor's rate u a variable
# that spec/controller.ha sets, for the system spec/controlled_finger.ha. Generated by
# tools/generate_finger.py --driven; do not edit by hand.
#
# It differs from spec/finger.ha in these places: u is a variable (the controller's command,
# counts per second, set by its resets) instead of an input; the controller gives the motor
# position g its flow (g' = +-speed while it drives, 0 otherwise) and keeps it in [0, 255], so
# the modes have no invariant; every transition into phase 4
# is labelled `stall`, the label of the controller's transitions into `stopped`; and it has no
# scenario and no properties of its own. spec/finger.ha's properties are proved there for every
# piecewise-constant u in [-1, 1]; every flow is proportional to u, so a run driven at speed s is
# such a run with time scaled by s and the same states: they hold here too. See
# docs/finger_model.md, "The controller".

automaton driven_finger {"""


def main():
    driven = "--driven" in sys.argv[1:]
    all_states = states()
    print(DRIVEN_HEADER if driven else """# One finger of the Robotiq 3-Finger Adaptive Gripper: the hybrid automaton of section 3 of
# G. Franchi and K. Hauser, "Technical Report: Use of Hybrid Systems to model the RobotiQ Adaptive
# Gripper" (Indiana University TR711). Generated by tools/generate_finger.py; do not edit by hand.
#
# State x = (theta1, theta2, theta3, g): joint angles in degrees (theta3 relative to link 2) and
# the motor position in counts. Input u in [-1, 1]: motor counts per second. Discrete state
# (c1, c2, c3, l1, l2, l3): c_i = 1 when link i is blocked by an object, l_i = 1 when it is at its
# upper joint limit, l3 = -1 when link 3 is at its lower limit. Modes are named c<c1c2c3>_l<l1l2l3>
# with n for -1. Joint ranges: docs/gripper_facts.md (Klamp't limits). See
# docs/finger_model.md for the phases, the transitions and every interpretation made.

automaton finger {""")
    print("""  param theta1_min [deg] = 0;
  param theta1_max [deg] = 70;
  param theta2_min [deg] = 0;
  param theta2_max [deg] = 90;
  param theta3_min [deg] = -55;
  param theta3_max [deg] = 43;
  # m1 = theta1_max / 140 and m2 = theta2_max / 100 (degrees per motor count), as in the report.
  param m1 [deg/count] = theta1_max / 140;
  param m2 [deg/count] = theta2_max / 100;
  # Link 3 reaches its upper limit in phase 3 this fraction of the way from g_s (where link 2
  # stopped) to 255: the report's one half (figure 4.1). m3_scale = (1 - f) / f scales the law so
  # that it does; `hybrid diagnose` fits the fraction (cause theta3_law).
  param theta3_fraction = 0.5;
  param m3_scale = (1 - theta3_fraction) / theta3_fraction;
  # Motor position at which link i first touches an object; 256 (beyond the motor range) = no
  # object. Issue-level scenarios set these; geometry-based contact replaces them later.
  # `in [0, 256]`: `hybrid check` proves properties for every object position (and none).
  param gob1 [count] = 256 in [0, 256];
  param gob2 [count] = 256 in [0, 256];
  param gob3 [count] = 256 in [0, 256];
  var theta1 [deg] in [theta1_min, theta1_max];
  var theta2 [deg] in [theta2_min, theta2_max];
  var theta3 [deg] in [theta3_min, theta3_max];
  var g [count] in [0, 255];
  # theta3 and g when link 2 was last blocked (set by the transition that blocks it): where the
  # phase-3 law of theta3 starts (decision C1).
  var theta3_s [deg] in [theta3_min, theta3_max];
  var g_s [count] in [0, 255];
  discrete c1, c2, c3, l1, l2, l3;""")
    print("  var u [count/s] in [-255, 255];" if driven else "  input u [count/s] in [-1, 1];")
    # Only the motor range is an invariant (the controller stops the motor at its ends). The joint
    # ranges are properties: the limit transitions must keep them, and `hybrid check` proves it.
    invariant = "g >= 0 and g <= 255"
    for s in all_states:
        c1, c2, c3, l1, l2, l3 = s
        p = phase(s)
        print(f"\n  # phase {p}")
        print(f"  mode {name(s)} (c1 = {c1}, c2 = {c2}, c3 = {c3}, l1 = {l1}, l2 = {l2}, "
              f"l3 = {l3}) {{")
        for var in ("theta1", "theta2", "theta3", "g"):
            if var in FLOWS[p] and not (driven and var == "g"):
                rhs = FLOWS[p][var]
                rhs = rate(rhs)  # phase 3: section 4's law (C1)
                print(f"    {var}' = {rhs};")
        if not driven:
            print(f"    inv {invariant};")
        print("  }")
    all_transitions = transitions(all_states)
    if driven:
        all_transitions = stall_labels(all_transitions)
    for tname, s, t, guard, label, resets in all_transitions:
        print(f"\n  transition {tname}: {name(s)} -> {name(t)} {{")
        print(f"    guard {guard};")
        if resets:
            print(f"    reset {resets};")
        if label:
            print(f"    label {label};")
        print("  }")
    if driven:
        print("""
  init c000_l000 { theta1 = 0; theta2 = 0; theta3 = 0; g = 0; theta3_s = 0; g_s = 0; u = 0; }
}""")
        return
    print("""
  init c000_l000 { theta1 = 0; theta2 = 0; theta3 = 0; g = 0; theta3_s = 0; g_s = 0; }

  # Close at full speed for 255 s (the finger stops against the palm at g = 240), hold, then open
  # at full speed back to g = 0 (the controller's position request: close, hold, open).
  scenario {
    until 530;
    u = step(0: 1, 255: 0, 265: -1, 505: 0);
  }

  # The report: no reachable state has c_i = l_i = 1.
  property never_contact_at_limit_1: never c1 == 1 and l1 == 1;
  property never_contact_at_limit_2: never c2 == 1 and l2 == 1;
  property never_contact_at_limit_3: never c3 == 1 and l3 == 1;
  # The joint ranges and the motor range.
  property theta1_range: always theta1 >= theta1_min and theta1 <= theta1_max;
  property theta2_range: always theta2 >= theta2_min and theta2 <= theta2_max;
  property theta3_range: always theta3 >= theta3_min and theta3 <= theta3_max;
  property motor_range: always g >= 0 and g <= 255;
  # The closed form's couplings (section 4), invariants of every run. They are what makes the
  # joint ranges provable by induction: `hybrid check spec/finger.ha` proves all of them together.
  # Link i at its limit sits exactly at it.
  property limits_exact: always (l1 == 0 or theta1 == theta1_max) and (l2 == 0 or theta2 == theta2_max) and (l3 <= 0 or theta3 == theta3_max) and (l3 >= 0 or theta3 == theta3_min);
  # The transmission: the motor counts spent on links 1 and 2 (m1, m2 degrees per count) add up
  # to g while link 2 moves, and to g_s once it is blocked.
  property transmission: always (c2 == 0 and l2 == 0 and theta1 / m1 + theta2 / m2 == g) or ((c2 == 1 or l2 == 1) and theta1 / m1 + theta2 / m2 == g_s);
  # Link 2 moves only once link 1 is blocked.
  property link2_waits_for_link1: always c1 == 1 or l1 == 1 or theta2 == theta2_min;
  # While link 2 moves, link 3 keeps its orientation: theta1 + theta2 + theta3 = 0, or theta3 at
  # its lower limit.
  property distal_coupling: always c2 == 1 or l2 == 1 or (l3 == 0 and theta1 + theta2 + theta3 == 0) or (l3 == -1 and theta1 + theta2 + theta3_min >= 0);
  # Once link 2 is blocked, theta3 follows section 4's law from (theta3_s, g_s) (decision C2).
  property phase3_law: always (c2 == 0 and l2 == 0) or ((theta3 - theta3_s) * (255 - g) == m3_scale * (theta3_max - theta3_s) * (g - g_s) and g >= g_s and theta3_s >= theta3_min and theta1 + theta2 + theta3_s >= 0 and (theta3_s == theta3_min or theta1 + theta2 + theta3_s == 0));
  # Reachability questions.
  property can_close_fully: reach l1 == 1 and l2 == 1;
}""")


if __name__ == "__main__":
    main()
