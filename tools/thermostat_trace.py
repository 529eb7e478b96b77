#!/usr/bin/env python3
"""Measured-looking traces of the thermostat, written from its closed form: the example data of
`hybrid diagnose` for the thermostat (data/thermostat_*.csv), one file per hidden defect.

An independent generator: it imports nothing of the project (standard library only) and never
runs `hybrid`, so that the data and the simulator are two separate computations of the same model
(tests/python/test_thermostat_data.py compares them). The plant of spec/thermostat.ha: the
temperature x relaxes towards the outside temperature u at rate a, plus heating power p while the
heater is on. Between switches, with u constant,

    off: x(t) = u + (x0 - u) e^{-a t}
    on:  x(t) = u + p/a + (x0 - u - p/a) e^{-a t}

and the level s is reached at t* = (1/a) ln((x0 - x_eq) / (s - x_eq)), x_eq the mode's
equilibrium (u, or u + p/a), when s lies between x0 and x_eq.

Models (--model):
  lazy    spec/thermostat.ha: lazy transitions, which the simulator fires at the invariant
          boundary, x = 18 going on and x = 22 going off (the guards allow x <= 19 and x >= 21:
          --switch-on in [18, 19] and --switch-off in [21, 22] are runs the model allows);
  urgent  spec/thermostat_urgent.ha: urgent transitions, guard x <= 18 going on and x >= 22 going
          off, invariants x >= 17 (off) and x <= 23 (on): --switch-on >= 17, --switch-off <= 23.

Defects: --heater P (the heating power, default 3), --switch-on S / --switch-off S (where the
controller switches), --bias B (a sensor offset: added to the measured x only; the controller
acts on the true temperature). Every run starts off at x = 20 with a constant input u; the runs
(--runs U,U,...) are sampled every --step minutes from 0 to --until, both included. Gaussian noise
of standard deviation --noise is added to every measured x, drawn in row order from
random.Random(--seed). Output (standard output): the comment line `# made by: COMMAND`, COMMAND
the full command line that writes this output again byte for byte (every option spelled out, to
be run from the repository's root), a comment line describing the data, then the CSV header
`run,time,u,x` and one row per sample; x printed with 4 decimals, or 10 with --noiseless (no
noise, for comparing with `hybrid simulate`).

Example: /usr/bin/python3 tools/thermostat_trace.py --heater 2.4 --seed 12 > data/thermostat_weak_heater.csv
"""

import argparse
import math
import random
import sys

A = 0.1         # 1/min, the relaxation rate of both models
X_INIT = 20.0   # degC, the initial temperature (init off { x = 20; })
MODELS = {
    # model: (spec file, default switch-on level, default switch-off level,
    #         allowed switch-on range, allowed switch-off range)
    "lazy": ("spec/thermostat.ha", 18.0, 22.0, (18.0, 19.0), (21.0, 22.0)),
    "urgent": ("spec/thermostat_urgent.ha", 18.0, 22.0, (17.0, math.inf), (-math.inf, 23.0)),
}


def number(text):
    """A finite float from the command line."""
    value = float(text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError("not a finite number: " + text)
    return value


def numbers(text):
    """A comma-separated list of finite floats (at least one)."""
    try:
        values = [number(part) for part in text.split(",")]
    except (ValueError, argparse.ArgumentTypeError):
        raise argparse.ArgumentTypeError("expected numbers separated by commas: " + text)
    return values


def spell(value):
    """A float as the shortest text that reads back to it: 3, 2.4, 0.25, -0.4."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def events(u, p, s_on, s_off, until, x0=X_INIT, a=A, on_delay=0.0):
    """The piecewise closed form of one run with constant input u: a list of segments
    (t_start, t_end, mode, x_start, x_eq), t_end = until for the last one. A segment starting at or
    beyond its switching level switches at once (the urgent guard holds on entry). With on_delay,
    the heater starts that long after x reaches s_on (x keeps cooling meanwhile)."""
    segments = []
    t, mode, x = 0.0, "off", x0
    for _ in range(100000):
        x_eq = u if mode == "off" else u + p / a
        level = s_on if mode == "off" else s_off
        if (mode == "off" and x <= level) or (mode == "on" and x >= level):
            t_switch = t  # already at the level: switch now
        elif (mode == "off" and x_eq < level) or (mode == "on" and x_eq > level):
            t_switch = t + math.log((x - x_eq) / (level - x_eq)) / a
        else:
            t_switch = math.inf  # the equilibrium does not reach the level
        if mode == "off" and on_delay > 0:
            t_switch += on_delay
        if t_switch >= until:
            segments.append((t, until, mode, x, x_eq))
            return segments
        if t_switch > t:
            segments.append((t, t_switch, mode, x, x_eq))
        if mode == "off" and on_delay > 0:
            x = x_eq + (x - x_eq) * math.exp(-a * (t_switch - t))
        else:
            x = level
        t = t_switch
        mode = "on" if mode == "off" else "off"
    raise RuntimeError("more than 100000 switches in one run (chattering thresholds?)")


def temperature(segments, t, a=A):
    """x at time t of the run given by its segments (at a switching instant, the segment it ends)."""
    for start, end, _, x0, x_eq in segments:
        if start <= t <= end:
            return x_eq + (x0 - x_eq) * math.exp(-a * (t - start))
    raise ValueError("time outside the run: %r" % t)


def main(argv):
    parser = argparse.ArgumentParser(
        description="Thermostat traces from the closed form (data for `hybrid diagnose`).",
        epilog="Writes CSV (run,time,u,x) to standard output; see the module docstring.")
    parser.add_argument("--model", choices=sorted(MODELS), default="lazy",
                        help="lazy: spec/thermostat.ha (default); urgent: spec/thermostat_urgent.ha")
    parser.add_argument("--heater", type=number, default=3.0, metavar="P",
                        help="heating power p in degC/min (default 3)")
    parser.add_argument("--bias", type=number, default=0.0, metavar="B",
                        help="sensor bias added to the measured x (default 0)")
    parser.add_argument("--switch-on", type=number, default=None, metavar="S",
                        help="level where heating starts (default 18)")
    parser.add_argument("--switch-off", type=number, default=None, metavar="S",
                        help="level where heating stops (default 22)")
    parser.add_argument("--switch-on-delay", type=number, default=0.0, metavar="D",
                        help="urgent model: the heater starts D min after x reaches the switch-on "
                             "level (default 0)")
    parser.add_argument("--noise", type=number, default=0.1, metavar="SIGMA",
                        help="standard deviation of the Gaussian noise on x (default 0.1)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the noise (default 1)")
    parser.add_argument("--runs", type=numbers, default=[10.0, 10.0, 5.0, 5.0], metavar="U,U,...",
                        help="the constant input u of each run (default 10,10,5,5)")
    parser.add_argument("--until", type=number, default=60.0, metavar="T",
                        help="length of each run in minutes (default 60)")
    parser.add_argument("--step", type=number, default=0.25, metavar="DT",
                        help="sampling period in minutes (default 0.25)")
    parser.add_argument("--noiseless", action="store_true",
                        help="no noise, x with 10 decimals (to compare with `hybrid simulate`)")
    args = parser.parse_args(argv)

    spec, default_on, default_off, on_range, off_range = MODELS[args.model]
    s_on = default_on if args.switch_on is None else args.switch_on
    s_off = default_off if args.switch_off is None else args.switch_off
    if not on_range[0] <= s_on <= on_range[1]:
        parser.error("--switch-on %s is outside [%s, %s], what %s allows"
                     % (spell(s_on), spell(on_range[0]), spell(on_range[1]), spec))
    if not off_range[0] <= s_off <= off_range[1]:
        parser.error("--switch-off %s is outside [%s, %s], what %s allows"
                     % (spell(s_off), spell(off_range[0]), spell(off_range[1]), spec))
    if not s_on < s_off:
        parser.error("--switch-on must be below --switch-off")
    if args.switch_on_delay < 0 or (args.switch_on_delay > 0 and args.model != "urgent"):
        parser.error("--switch-on-delay must be >= 0, and only the urgent model has one (a lazy "
                     "transition already fires at the invariant's boundary)")
    if args.heater <= 0 or args.noise < 0 or args.until <= 0 or args.step <= 0:
        parser.error("--heater, --until and --step must be positive, --noise not negative")
    samples = int(round(args.until / args.step))
    if abs(samples * args.step - args.until) > 1e-9 * args.until or samples > 1000000:
        parser.error("--until must be a multiple of --step (at most 1000000 samples)")
    for u in args.runs:
        if not -20 <= u <= 30:
            parser.error("input u = %s is outside the models' range [-20, 30]" % spell(u))

    command = ["/usr/bin/python3", "tools/thermostat_trace.py", "--model", args.model,
               "--heater", spell(args.heater), "--bias", spell(args.bias),
               "--switch-on", spell(s_on), "--switch-off", spell(s_off)]
    if args.switch_on_delay > 0:
        command += ["--switch-on-delay", spell(args.switch_on_delay)]
    if args.noiseless:
        command += ["--noiseless"]
    else:
        command += ["--noise", spell(args.noise), "--seed", str(args.seed)]
    command += ["--runs", ",".join(spell(u) for u in args.runs),
                "--until", spell(args.until), "--step", spell(args.step)]

    out = sys.stdout
    out.write("# made by: " + " ".join(command) + "\n")
    out.write("# SYNTHETIC data (closed form, not measured): the thermostat of %s, %d run(s) from x = 20"
              " (off), u constant per run, x sampled every %s min for %s min%s\n"
              % (spec, len(args.runs), spell(args.step), spell(args.until),
                 "" if args.noiseless else ", Gaussian noise"))
    out.write("run,time,u,x\n")
    rng = random.Random(args.seed)
    x_format = "%.10f" if args.noiseless else "%.4f"
    for run, u in enumerate(args.runs, start=1):
        segments = events(u, args.heater, s_on, s_off, args.until, on_delay=args.switch_on_delay)
        for k in range(samples + 1):
            t = min(k * args.step, args.until)
            x = temperature(segments, t) + args.bias
            if not args.noiseless:
                x += rng.gauss(0.0, args.noise)
            out.write("%d,%.10g,%s,%s\n" % (run, t, spell(u), x_format % x))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
