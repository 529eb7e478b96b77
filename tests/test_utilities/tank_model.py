"""The tank of issue 12, shared by the Python tests (tests/python/): h rises at 0.5 + d per
second with the input d in [-0.2, 0], so from h = 5 it passes 6 and 7 (stays_below_6 violated,
reaches_7 reachable) but the invariant keeps it at most 8 (below_8 proved). The same model is
in tests/solvers/verification/property_prover_test.cc (C++, without below_8)."""

import textwrap

TANK = textwrap.dedent("""\
    automaton tank {
      var h in [0, 10];
      input d in [-0.2, 0];
      mode fill { h' = 0.5 + d; inv h <= 8; }
      init fill { h = 5; }
      property stays_below_6: always h <= 6;
      property reaches_7: reach h >= 7;
      property below_8: always h <= 8;
    }
    """)
