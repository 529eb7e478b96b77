"""hybrid: hybrid automata from Python (docs/python.md).

The C++ library behind the ``hybrid`` command line, in-process:

- :func:`finger_angles` -- the Robotiq finger's closed-form (quasistatic) joint angles, vectorised
  over numpy arrays of motor positions;
- :func:`load` -- a model (``.ha``, or SpaceEx ``.xml`` with its ``.cfg``) to inspect
  (:meth:`Model.info`), draw (:meth:`Model.dot`), simulate (:meth:`Model.simulate`) and check
  (:meth:`Model.check`).

Errors in a model raise :class:`ModelError` (a ``ValueError``) whose message names the file, line
and column, as the command line does; bad arguments raise ``ValueError`` or ``KeyError``.
"""

import json as _json

from . import _hybrid

ModelError = _hybrid.ModelError

__all__ = ["ModelError", "Model", "finger_angles", "load"]


def finger_angles(g, gob1=None, gob2=None, gob3=None, model=None):
    """Joint angles (theta1, theta2, theta3) in degrees of one finger closing to motor position g.

    The report's closed form (Franchi and Hauser's tables with the decisions of
    docs/finger_model.md), the numbers of ``hybrid finger --g G --json``.

    Args:
        g: a motor position in [0, 255] (counts) or an array of them (any shape; read flat).
        gob1, gob2, gob3: the motor positions at which links 1, 2, 3 meet an object
            (``--gob1..3``); None: never.
        model: path of a finger model like spec/finger.ha whose constants (joint ranges,
            phase-3 fraction) replace the report's.

    Returns:
        A float64 array of shape (n, 3), n the number of values of g (1 for a number).
        theta3 is relative to link 2. Computed in C++ with the GIL released.

    Raises:
        ValueError: a motor position outside [0, 255] or NaN, or a model that is not a finger.
        ModelError: a model file that does not parse.
    """
    return _hybrid.finger_angles(g, gob1, gob2, gob3, model)


class Model:
    """A hybrid automaton (or a system of them) read from a file; see :func:`load`."""

    def __init__(self, path):
        self._model = _hybrid.Model(str(path))

    @property
    def path(self):
        """The file the model was read from."""
        return self._model.path

    @property
    def name(self):
        """The model's name (its automaton or system)."""
        return self._model.name

    def info(self):
        """Everything the model declares, as ``hybrid info --json`` reports it (a dict)."""
        return _json.loads(self._model.info_json())

    def dot(self, product=False):
        """The mode graph in Graphviz DOT (``hybrid dot``); ``product=True`` draws the product."""
        return self._model.dot(product)

    def simulate(self, until=None, inputs=None, sample=None, parameters=None):
        """Simulates from the initial state with exact event location (``hybrid simulate``).

        Args:
            until: the horizon in model time units; None: the model's scenario's.
            inputs: {input name: signal}, a signal being a number (constant), a list of
                (time, value) steps, or a signal in the language's syntax, e.g.
                ``"ramp(0: 0, 2: 1)"``; inputs left out follow the scenario (or stay at 0).
            sample: > 0 also records the state every ``sample`` time units.
            parameters: {parameter name: value} overrides.

        Returns:
            A dict: ``status`` ("completed" or why the run stopped early) and ``message``;
            ``time`` (numpy array of the recorded instants: the start, samples, both sides of
            every jump, the end); ``states`` ({variable name: numpy array}, aligned with
            ``time``); ``modes`` (the mode at each instant, ``A.m|B.n`` for several components);
            ``events`` (one dict per jump: time, transitions, label, modes_before, modes_after).
        """
        return self._model.simulate(until, dict(inputs or {}), sample, dict(parameters or {}))

    def check(self, properties=None, method="auto", budget=60.0, depth=10):
        """Checks the model's properties (``hybrid check --json``).

        Args:
            properties: names of properties to check; None: every declared one.
            method: "auto", "reach" (polyhedral reachability), "prove" (SMT k-induction) or
                "sample" (random simulations).
            budget: the solver budget of "prove", in budget seconds.
            depth: the longest counterexample "prove" searches, in steps.

        Returns:
            The report of ``hybrid check --json`` (docs/cli.md): ``properties`` lists each (``name``)
            property's ``verdict`` (proved, violated, reachable, unreachable, unknown),
            ``method``, ``reason`` and, for a violation or a witness, its ``trace``.
        """
        report = self._model.check_json(list(properties or []), method, float(budget), int(depth))
        return _json.loads(report)

    def __repr__(self):
        return "hybrid.Model(%r)" % self.path


def load(path):
    """Reads the model at ``path`` (a ``.ha`` file, or SpaceEx ``.xml`` with the ``.cfg`` of
    the same name next to it). Raises ModelError (file:line:col: message) if it does not parse,
    OSError-like ValueError if it cannot be read."""
    return Model(path)
