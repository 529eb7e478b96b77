"""A plain-Python quasistatic Robotiq finger: the closed form of section 4 of Franchi and Hauser's
report (tables 4.1 and 4.2) with the project's decisions (docs/finger_model.md: C2, phase 3
continued from theta3_s; D3, the free finger stops against the palm at g = 240), written apart
from the C++ closed form (gripper/finger_closed_form.cc), in the style of Klamp't's Python
emulator: one query at a time, plain floats.

Used as the reference of tools/bench_python_finger.py (speed) and as an independent oracle of
tests/python/ (values). Contacts: gob1..gob3 are the motor positions at which links 1..3 meet an
object (None: never).
"""

THETA1_MAX, THETA2_MAX = 70.0, 90.0      # joint upper limits (degrees)
THETA3_MIN, THETA3_MAX = -55.0, 43.0     # link 3's range
M1 = THETA1_MAX / 140.0                  # link 1 rate (degrees per count)
M2 = THETA2_MAX / 100.0                  # link 2 rate
MOTOR_MAX = 255.0
PALM = 240.0                             # D3: the free finger stops against the palm
NEVER = float("inf")


def finger_angles(g, gob1=None, gob2=None, gob3=None):
    """(theta1, theta2, theta3) in degrees at motor position g in [0, 255]."""
    if not 0.0 <= g <= MOTOR_MAX:
        raise ValueError("g must be in [0, 255]")
    gob1 = NEVER if gob1 is None else gob1
    gob2 = NEVER if gob2 is None else gob2
    gob3 = NEVER if gob3 is None else gob3
    g = min(g, gob3)                     # link 3 blocked: the finger stops (phase 4)
    # Phases 1 and 1': link 1 turns (theta3 keeps link 3 vertical down to its minimum) until
    # link 1 stops (object or limit) or link 2 is blocked.
    g1 = min(gob1, THETA1_MAX / M1, gob2)
    if g <= g1:
        theta1 = M1 * g
        return (theta1, 0.0, max(-theta1, THETA3_MIN))
    theta1 = M1 * g1
    # Phases 2 and 2': link 2 turns until it stops (object or limit).
    g2 = g1 if gob2 <= g1 else min(gob2, g1 + THETA2_MAX / M2)
    if g <= g2:
        theta2 = M2 * (g - g1)
        return (theta1, theta2, max(-(theta1 + theta2), THETA3_MIN))
    theta2 = M2 * (g2 - g1)
    theta3_s = max(-(theta1 + theta2), THETA3_MIN)
    if g2 >= PALM and gob2 > g2 and gob1 > THETA1_MAX / M1:
        # Links 1 and 2 reached their limits by themselves: the palm stops the finger (D3). (With
        # a contact exactly at a limit, gob1 = 140, the contact table applies: C7.)
        return (theta1, theta2, theta3_s)
    # Phase 3: theta3 = theta3_s + (theta3_max - theta3_s) (g - g2) / (255 - g), reaching
    # theta3_max half way from g2 to 255 (then phase 4).
    g = min(g, (MOTOR_MAX + g2) / 2.0)
    return (theta1, theta2, theta3_s + (THETA3_MAX - theta3_s) * (g - g2) / (MOTOR_MAX - g))
