"""hybrid: hybrid automata from Python (docs/python.md).

The C++ library behind the ``hybrid`` command line, in-process:

- :func:`finger_angles` -- the Robotiq finger's closed-form (quasistatic) joint angles, vectorised
  over numpy arrays of motor positions;
- :func:`hand` -- the three-finger hand closing on objects (``hybrid hand --json``);
- :func:`diagnose` -- measured finger data against the model (``hybrid diagnose --json``);
- :func:`load` -- a model (``.ha``, or SpaceEx ``.xml`` with its ``.cfg``) to inspect
  (:meth:`Model.info`), draw (:meth:`Model.dot`), simulate (:meth:`Model.simulate`) and check
  (:meth:`Model.check`);
- :func:`set_log_level` -- what the engines do, logged to standard error.

Errors in a model raise :class:`ModelError` (a ``ValueError``) whose message names the file, line
and column, as the command line does; bad arguments raise ``ValueError`` (its message names the
keyword argument, e.g. ``method must be 'auto', 'reach', 'flowpipe', 'prove' or 'sample', not 'x'``, and its
attribute ``argument`` is that name) or ``KeyError``; a bug of the library raises
``RuntimeError`` ("internal error ...").

Ctrl-C stops a long call (:meth:`Model.check`, :meth:`Model.simulate`, :func:`diagnose`,
:func:`finger_angles` on large arrays) at once with ``KeyboardInterrupt``: called from the main
thread, the first three compute in a child process that is killed (:meth:`Model.simulate` after
its first 20000 integration passes, which run in the process: docs/python.md).
"""

import json as _json

from . import _hybrid
from ._version import __version__

ModelError = _hybrid.ModelError
DataError = _hybrid.DataError

__all__ = ["DataError", "Gripper", "ModelError", "Model", "diagnose", "finger", "finger_angles",
           "finger_sweep", "hand", "hand_sweep", "joint_state", "load", "set_log_level"]


def set_log_level(level):
    """Logs what the engines do (solver queries, replays, induction steps) to standard error.

    Args:
        level: "debug", "info" or "warning": the lowest level logged, as ``hybrid --log LEVEL``
            does; None: no log (the default).

    The lines are ``hybrid [LEVEL] topic: message``, written to the process's standard error
    (file descriptor 2), not through Python's ``logging``: the engines log from worker threads and
    from the child processes long calls run in.

    Raises:
        ValueError: any other level.
    """
    _hybrid.set_log_level(level)


def finger_angles(g, gob1=None, gob2=None, gob3=None, model=None, out=None):
    """Joint angles (theta1, theta2, theta3) in degrees of one finger closing to motor position g.

    The report's closed form (Franchi and Hauser's tables with the decisions of
    docs/finger_model.md), the numbers of ``hybrid finger --g G --json``.

    Args:
        g: a motor position in [0, 255] (counts) or an array of them (any shape; read flat).
        gob1, gob2, gob3: the motor positions at which links 1, 2, 3 meet an object
            (``--gob1..3``); None: never.
        model: path of a finger model like spec/finger.ha whose constants (joint ranges,
            phase-3 fraction) replace the report's.
        out: a writable C-contiguous float64 array of shape (n, 3) to write the angles into
            (returned); None: a new array. A batch computed again into the same array pays no
            allocation or page faults.

    Returns:
        A float64 array of shape (n, 3), n the number of values of g (1 for a number).
        theta3 is relative to link 2. Computed in C++ with the GIL released.

    Raises:
        ValueError: a motor position outside [0, 255] or NaN, or a model that is not a finger.
        ModelError: a model file that does not parse.
    """
    if model is None and out is None and type(g) in (float, int):  # one position: no batch
        return _hybrid.finger_angles_one(g, gob1, gob2, gob3)
    return _hybrid.finger_angles(g, gob1, gob2, gob3, model, out)


class Model:
    """A hybrid automaton (or a system of them) read from a file; see :func:`load`."""

    def __init__(self, path, config=None):
        self._model = _hybrid.Model(str(path), None if config is None else str(config))

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

    def simulate(self, until=None, inputs=None, sample=None, parameters=None, init=None,
                 tolerance=None):
        """Simulates from the initial state with exact event location (``hybrid simulate``).

        Args:
            until: the horizon in model time units; None: the model's scenario's (for a SpaceEx
                model, its configuration's ``time-horizon``).
            inputs: {input name: signal}, a signal being a number (constant), a list of
                (time, value) steps, or a signal in the language's syntax, e.g.
                ``"ramp(0: 0, 2: 1)"``; inputs left out follow the scenario (or stay at 0).
            sample: > 0 also records the state every ``sample`` time units.
            parameters: {parameter name: value} overrides.
            init: {continuous variable name: value}, the run's initial values (``A.x`` in a
                composed system); ValueError for a name that is no continuous variable, a value
                that is not finite or lies outside the variable's declared domain.
            tolerance: the integrator's relative tolerance (its absolute one is a hundredth of
                it); None: the defaults, 1e-10 and 1e-12 (docs/simulation.md).

        Returns:
            A dict: ``hybrid simulate --json``'s members (``status``, ``message``, ``until``,
            ``final``: a state {time, mode, values}, ``steps``, ``events``: one dict per jump
            with time, cause, transitions, label, mode_before, mode_after, before and after,
            and ``zeno`` when detected), plus the trajectory as numpy arrays: ``time`` (the
            recorded instants: the start, samples, both sides of every jump, the end),
            ``states`` ({variable name: numpy array}, aligned with ``time``) and ``modes`` (the
            mode at each instant, ``A.m|B.n`` for several components).
        """
        return self._model.simulate(until, dict(inputs or {}), sample, dict(parameters or {}),
                                    dict(init or {}), tolerance)

    def check(self, properties=None, method="auto", budget=60.0, depth=10):
        """Checks the model's properties (``hybrid check --json``).

        Args:
            properties: names of properties to check; None: every declared one.
            method: "auto", "reach" (polyhedral reachability), "flowpipe" (Taylor flowpipes),
                "prove" (SMT k-induction) or "sample" (random simulations).
            budget: the solver budget of "prove", in budget seconds.
            depth: the longest counterexample "prove" searches, in steps.

        Returns:
            The report of ``hybrid check --json`` (docs/cli.md): ``properties`` lists each (``name``)
            property's ``verdict`` (proved, violated, reachable, unreachable, unknown),
            ``method``, ``reason`` and, for a violation or a witness, its ``trace``.
        """
        report = self._model.check_json(list(properties or []), method, float(budget), int(depth))
        return _json.loads(report)

    def reach_set(self, properties=None, budget=60.0, order=6, step=0.0):
        """The flowpipe of ``hybrid check --method flowpipe`` (docs/verification.md): one box per
        Taylor step of every mode entry, over-approximating every state reachable then.

        Args:
            properties: names of the properties that set the horizon (their ``within`` and the
                scenario's ``until``); None: every declared one.
            budget: the flowpipe's budget in budget seconds of Taylor steps.
            order: the Taylor order (1 to 12); step: the time step (0: automatic).

        Returns:
            A dict: ``variables`` (names), ``mode`` (the mode of each box), ``time`` (n x 2:
            each box's time span; inf for a positively invariant box), ``lo`` and ``hi``
            (n x len(variables): the box's bounds). Raises ValueError for a model whose flows
            are not polynomial.
        """
        return self._model.reach_set(list(properties or []), float(budget), int(order),
                                     float(step))

    def reach_vertices(self, x, y, **kwargs):
        """The flowpipe projected on variables ``x`` and ``y`` as an (n, 4, 2) numpy array: the
        corners of each box counter-clockwise, ready for matplotlib's PolyCollection. Takes the
        arguments of reach_set."""
        import numpy
        reach = self.reach_set(**kwargs)
        names = reach["variables"]
        if x not in names or y not in names:
            raise ValueError("axes must be variables of the model: %s" % ", ".join(names))
        i, j = names.index(x), names.index(y)
        lo, hi = reach["lo"], reach["hi"]
        return numpy.stack([numpy.stack([lo[:, i], lo[:, j]], axis=1),
                            numpy.stack([hi[:, i], lo[:, j]], axis=1),
                            numpy.stack([hi[:, i], hi[:, j]], axis=1),
                            numpy.stack([lo[:, i], hi[:, j]], axis=1)], axis=1)

    def __repr__(self):
        return "hybrid.Model(%r)" % self.path


def load(path, config=None):
    """Reads the model at ``path`` (a ``.ha`` file, or SpaceEx ``.xml`` with the ``.cfg`` of
    the same name next to it, or the configuration ``config`` when given). Raises ModelError
    (file:line:col: message) if it does not parse, OSError-like ValueError if it cannot be read,
    ValueError if ``config`` is given with a model that is not SpaceEx's."""
    return Model(path, config)


def hand(objects=(), mode="basic", spread=None, g=255.0, g_a=None, g_b=None, g_c=None):
    """The three-finger hand closing on objects, quasistatically (``hybrid hand --json``).

    Args:
        objects: object descriptions in the palm's x-y plane (metres), as ``--object`` takes
            them: ``"circle:X,Y,R"`` (a cylinder across the hand) or
            ``"segment:X1,Y1,X2,Y2[,R]"``.
        mode: the operating mode setting the spread: "basic", "wide", "pinch" or "scissor".
        spread: the spread motor position in [0, 255] (overrides the mode's).
        g: one motor command for all fingers, in [0, 255].
        g_a, g_b, g_c: per-finger commands (override g).

    Returns:
        The report of ``hybrid hand --json`` (docs/cli.md): ``spread``, ``spread_angle_deg``,
        ``fingers`` (per finger: ``finger``, ``command``, ``motor``, ``theta1..3``, ``phase``,
        ``mode``, ``contacts`` with the link, motor position and what blocks it) and
        ``finger_touches``.

    Raises:
        ValueError: a malformed object or a position out of range, or an object that overlaps
            the palm or an open finger. Objects out of reach are an outcome: ``status`` (see
            :func:`hand_sweep`).
    """
    report = _hybrid.hand_json(list(objects), mode, spread, float(g), g_a, g_b, g_c)
    return _json.loads(report)


def joint_state(objects=(), mode="basic", spread=None, g=255.0, g_a=None, g_b=None, g_c=None):
    """The hand of :func:`hand` (same arguments) at the end of its closing, as the joints of the
    ROS description (ros-industrial/robotiq's robotiq_3f_gripper_visualization; the mapping and
    its sources: docs/robot_frames.md), like a sensor_msgs/JointState.

    Returns:
        A dict: ``name`` (the 11 joints, in the ROS joint-state publisher's order), ``position``
        (radians, within the description's limits), ``model_position`` (the model's values in
        the same frame before clamping into the limits) and ``clamped`` (the joints where the two
        differ). Raises as :func:`hand`.
    """
    report = _hybrid.hand_json(list(objects), mode, spread, float(g), g_a, g_b, g_c, True)
    return _json.loads(report)["joint_state"]


class Gripper:
    """A stateful emulator of the gripper for a physics simulator's loop (docs/gripper_emulator.md):
    write its registers (:meth:`command`), advance time (:meth:`step`), read joint states and
    status registers back. It steps the composed automata of spec/gripper.ha (three fingers, the
    scissor axis and their position controllers), compiled once; each step continues the run
    from where the last one stopped.

    Args:
        model: a system like spec/gripper.ha; None: the bundled one.
        objects: object descriptions in the palm's x-y plane (metres), as :func:`hand` takes
            them; the fingers' contacts with them are those of :func:`hand`.

    Starts reset (``gACT`` 0) and open, with the scissor axis at 0 (fingers B and C apart).
    """

    def __init__(self, model=None, objects=()):
        self._gripper = _hybrid.Gripper(None if model is None else str(model), list(objects))

    def command(self, registers=None, **more):
        """Writes output registers by their manual names, e.g. ``command(rACT=1, rGTO=1,
        rPRA=255)`` (or a dict); registers not named keep their values. They take effect from
        the next step. Flags rACT, rGTO, rATR, rGLV, rICF, rICS are 0 or 1; rMOD is 0 basic,
        1 pinch, 2 wide, 3 scissor; rPRx, rSPx, rFRx (x = A, B, C, S) are 0..255.

        Raises:
            ValueError: an unknown register or a value out of its range.
        """
        values = dict(registers or {})
        values.update(more)
        self._gripper.command({k: int(v) for k, v in values.items()})

    def step(self, dt):
        """Advances ``dt`` seconds (0 < dt <= 10) and returns the state reached: a dict with
        ``time``, ``status`` (the input registers: gACT, gMOD, gGTO, gIMC, gSTA, gFLT and per
        axis A, B, C, S: gDTx, gPRx, gPOx, gCUx), ``theta`` (3 x 3, the report's angles of fingers
        A, B, C in degrees), ``motor`` (A, B, C), ``scissor``, ``spread_angle`` (degrees),
        ``joint_state`` (the ROS description's joints, as :func:`joint_state`), ``simulation``
        ("completed", or how the step's run ended) and ``message``."""
        return self._gripper.step(float(dt))

    @property
    def state(self):
        """The state after the last step (or at the start), as :meth:`step` returns it."""
        return self._gripper.state()


def finger(g=255.0, objects=(), gob1=None, gob2=None, gob3=None):
    """One finger closing to motor position g, on contact positions or objects by geometry
    (``hybrid finger --g G --json``).

    Args:
        g: the motor position in [0, 255].
        objects: object descriptions in the finger's plane (metres), as :func:`hand` takes them.
        gob1, gob2, gob3: the motor positions at which links 1..3 meet an object (instead of
            objects).

    Returns:
        The report of ``hybrid finger --json``: the configuration at g (``motor``,
        ``theta1..3``, ``phase``, ``mode``, ``discrete``), ``contacts``, ``stop``; with objects
        also ``status`` ("contact", "free": the first contact comes after g, "out_of_reach")
        and ``first_contact``.

    Raises:
        ValueError: a malformed object, a position out of range, or an object that overlaps the
            palm or the open finger.
    """
    return _json.loads(_hybrid.finger_json(float(g), gob1, gob2, gob3, list(objects)))


def _sweep_arrays(result, fingers):
    import numpy
    n = len(result["status"])
    result["status"] = numpy.array(result["status"], dtype=str).reshape(n)
    result["message"] = numpy.array(result["message"], dtype=str).reshape(n)
    for key in ("phase", "mode"):
        result[key] = numpy.array(result[key], dtype=str).reshape(n, fingers)
    result["contact_by"] = numpy.array(result["contact_by"], dtype=str).reshape(n, fingers, 3)
    return result


def hand_sweep(objects, offsets, mode="basic", spread=None, g=255.0, g_a=None, g_b=None,
               g_c=None, threads=2):
    """A grasp sweep: :func:`hand` with its objects moved by each row of ``offsets``, in C++ on
    ``threads`` worker threads (docs/python.md, "Grasp sweeps").

    Args:
        objects: object descriptions in the palm's x-y plane (metres), as :func:`hand` takes them.
        offsets: an array of shape (n, 2): each row moves every object by (dx, dy) metres.
        mode, spread, g, g_a, g_b, g_c: as for :func:`hand`.
        threads: worker threads (1 to 64); the result does not depend on it.

    Returns:
        A dict of numpy arrays, one row per offset, each row what :func:`hand` reports for the
        moved objects: ``status`` (n,) "contact", "free", "out_of_reach" or "invalid" (objects
        overlapping the palm or an open finger; ``message`` (n,) says why), ``first_contact``
        (n,), and per finger A, B, C: ``motor`` (n, 3), ``theta`` (n, 3, 3) degrees, ``phase``
        and ``mode`` (n, 3), ``stop`` (n, 3) (inf: none), per link ``contact_g`` (n, 3, 3) (NaN:
        none) and ``contact_by`` (n, 3, 3) ("object 1", "palm", "finger B" or "").

    Raises:
        ValueError: bad settings (as :func:`hand`), offsets that are not (n, 2) or not finite.
    """
    result = _hybrid.hand_sweep(list(objects), offsets, mode, spread, float(g), g_a, g_b, g_c,
                                int(threads))
    return _sweep_arrays(result, 3)


def finger_sweep(objects, offsets, g=255.0, threads=2):
    """A grasp sweep of one finger: :func:`finger` at motor position g with its objects moved by
    each row of ``offsets`` ((n, 2), metres, the finger's plane). Returns the arrays of
    :func:`hand_sweep` with one finger: ``motor`` (n, 1), ``theta`` (n, 1, 3), ...; ``status``
    is relative to g ("free": the first contact comes later)."""
    return _sweep_arrays(_hybrid.finger_sweep(list(objects), offsets, float(g), int(threads)), 1)


def diagnose(*files, model=None, significance=25.0, threads=2, noise=None):
    """Measured data against a model (``hybrid diagnose [MODEL] DATA --json``; docs/diagnosis.md).

    ``diagnose(model, data)``: a trace of any model (a CSV with columns ``run``, ``time``, the
    model's inputs and variables); ``diagnose(data)`` or ``diagnose(data, model=...)``: the
    finger's measured runs (default model: the bundled spec/finger.ha).

    Args:
        files: ``model, data`` or ``data``.
        model: the model, when ``data`` is given alone.
        significance: how much a cause must improve the fit to be named.
        threads: worker threads.
        noise: {variable: standard deviation} in place of the estimated noise (traces only).

    Returns:
        The report of ``hybrid diagnose --json``: the cause named (``cause``, a list), the fitted
        parameters, held-out errors and where the residual is. For a trace of any model also
        ``curves``: per run a dict with ``run``, ``time`` (a numpy array) and ``measured``,
        ``baseline``, ``extended`` ({variable: numpy array}, NaN where missing). Nothing is
        written.

    Raises:
        DataError: bad data (a ValueError naming the file, line and column).
    """
    if len(files) not in (1, 2):
        raise TypeError("diagnose() takes (model, data) or (data)")
    if len(files) == 2:
        if model is not None:
            raise TypeError("diagnose(): the model is given twice")
        model, data = files
    else:
        data = files[0]
    if _hybrid.is_trace_file(str(data)):
        if model is None:
            raise ValueError(f"{data} is a trace (it has a 'time' column): give its model, "
                             "diagnose(model, data)")
        items = [f"{k}={v!r}" for k, v in (noise or {}).items()]
        report = _json.loads(_hybrid.diagnose_model_json(str(model), str(data),
                                                         float(significance), int(threads),
                                                         items))
        import numpy
        for curve in report["curves"]:
            curve["time"] = numpy.asarray(curve["time"], dtype=float)
            for key in ("measured", "baseline", "extended"):
                curve[key] = {name: numpy.array([numpy.nan if v is None else v for v in values])
                              for name, values in curve[key].items()}
        return report
    if noise:
        raise ValueError("noise applies to a trace of any model, not to the finger's data")
    report = _hybrid.diagnose_json(str(data), None if model is None else str(model),
                                   float(significance), int(threads))
    return _json.loads(report)
