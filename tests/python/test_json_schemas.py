"""The JSON Schemas of every command's `--json` document (docs/schemas/, docs/cli.md "JSON output").

Each command runs on the bundled models and its output is validated against its schema; edited
outputs (an extra member, a renamed member, a string where an array belongs) must fail, so the
schemas are known to bite. The schemas themselves must be valid draft 2020-12 schemas whose
`$ref`s all resolve among the files of docs/schemas/, and the field listings of docs/cli.md are
derived from them (`schema_paths`), so that the documentation cannot drift from the schemas.
Run by ctest as part of `python_tests`; needs the `jsonschema` module (Debian
python3-jsonschema)."""

import copy
import glob
import json
import os
import re
import subprocess
import sys
import textwrap
from urllib.parse import urldefrag, urljoin

import pytest
from jsonschema import Draft202012Validator

try:  # jsonschema >= 4.18 resolves references through `referencing`
    from referencing import Registry
    from referencing.jsonschema import DRAFT202012
except ImportError:  # Debian bookworm's jsonschema 4.10
    Registry = None
    from jsonschema import RefResolver

SOURCE = os.environ.get("HYBRID_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BINARY = os.environ.get("HYBRID_BINARY", os.path.join(SOURCE, "build", "bin", "hybrid"))
SCHEMA_DIR = os.path.join(SOURCE, "docs", "schemas")
SPEC = os.path.join(SOURCE, "spec")
sys.path.insert(0, os.path.join(SOURCE, "tests", "test_utilities"))
from tank_model import TANK  # noqa: E402
BENCH = os.path.join(SOURCE, "spec", "benchmarks")


def load_schemas():
    schemas = {}
    for path in sorted(glob.glob(os.path.join(SCHEMA_DIR, "*.schema.json"))):
        with open(path) as f:
            schemas[os.path.basename(path)] = json.load(f)
    return schemas


SCHEMAS = load_schemas()
DOCUMENTS = ["info.schema.json", "simulate.schema.json", "check.schema.json", "finger.schema.json",
             "finger_batch.schema.json", "hand.schema.json", "diagnose.schema.json",
             "diagnose_model.schema.json"]


def validator(name):
    """A validator of schema `name` whose references resolve among the files of docs/schemas/
    (each schema's `$id` is its file name, so relative references name files)."""
    schema = SCHEMAS[name]
    if Registry is not None:
        registry = Registry().with_resources(
            (s["$id"], DRAFT202012.create_resource(s)) for s in SCHEMAS.values())
        return Draft202012Validator(schema, registry=registry)
    store = {s["$id"]: s for s in SCHEMAS.values()}
    return Draft202012Validator(schema, resolver=RefResolver.from_schema(schema, store=store))


def errors(name, document):
    return [f"{'/'.join(map(str, e.absolute_path))}: {e.message}"
            for e in validator(name).iter_errors(document)]


def assert_valid(name, document):
    found = errors(name, document)
    assert not found, "\n".join(found[:20])


def run(*args, codes=(0,)):
    out = subprocess.run([BINARY, *args], capture_output=True, text=True)
    assert out.returncode in codes, f"{args}: exit {out.returncode}\n{out.stderr}"
    return json.loads(out.stdout)


# ---------------------------------------------------------------------------------------------
# The schemas as schemas.

def test_the_schema_files_are_the_documented_ones():
    assert sorted(SCHEMAS) == sorted(DOCUMENTS + ["common.schema.json"])
    for name, schema in SCHEMAS.items():
        assert schema["$id"] == name
        assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"


@pytest.mark.parametrize("name", sorted(SCHEMAS))
def test_each_schema_is_a_valid_2020_12_schema(name):
    Draft202012Validator.check_schema(SCHEMAS[name])


def references(node):
    if isinstance(node, dict):
        for key, value in node.items():
            if key == "$ref":
                yield value
            else:
                yield from references(value)
    elif isinstance(node, list):
        for value in node:
            yield from references(value)


def resolve(base, ref):
    """The schema that `ref` (in the document `base`) names, read from SCHEMAS by hand."""
    url, fragment = urldefrag(urljoin(base, ref))
    node = SCHEMAS[url]
    for part in filter(None, fragment.split("/")):
        node = node[part.replace("~1", "/").replace("~0", "~")]
    return url, node


@pytest.mark.parametrize("name", sorted(SCHEMAS))
def test_every_reference_resolves(name):
    refs = list(references(SCHEMAS[name]))
    if name != "common.schema.json":
        assert any(r.startswith("common.schema.json#") for r in refs)  # the shared vocabulary
    v = validator(name)
    for ref in refs:
        target = urljoin(name, ref)
        if Registry is not None:
            resolved = v._resolver.lookup(target).contents
        else:
            resolved = v.resolver.resolve(target)[1]
        assert isinstance(resolved, dict) and resolved == resolve(name, ref)[1], ref


def subschemas(node):
    """The schemas directly inside schema `node` (of the keywords these files use; not the
    conditions if/then/else, which only narrow members described elsewhere)."""
    for key in ("properties", "$defs", "dependentSchemas"):
        yield from node.get(key, {}).values()
    for key in ("allOf", "anyOf", "oneOf", "prefixItems"):
        yield from node.get(key, [])
    for key in ("items", "additionalProperties", "unevaluatedProperties", "propertyNames", "not"):
        if isinstance(node.get(key), dict):
            yield node[key]


def test_every_member_is_described():
    def check(node, where):
        for key, member in node.get("properties", {}).items():
            assert "description" in member, f"{where}: {key}"
        for sub in subschemas(node):
            check(sub, where)

    for name, schema in SCHEMAS.items():
        check(schema, name)
        assert schema.get("description") and schema.get("title"), name
    for name, definition in SCHEMAS["common.schema.json"]["$defs"].items():
        assert definition.get("description"), name


# ---------------------------------------------------------------------------------------------
# The commands' outputs validate.

# A small automaton with what the bundled models lack: a bounded reach (`within`), a range of
# initial values, a parameter range, a discrete variable, an unreachable and a terminal mode.
PROBE = textwrap.dedent("""\
    automaton probe {
      param k [1/s] = 1 in [0.5, 2];
      var x [m] in [0, 100];
      discrete d;
      input u in [0, 1];
      mode a (d = 0) { x' = k + u; inv x <= 10; }
      mode b (d = 1) { x' = 0; }
      mode lost (d = 2) { }
      transition t: a -> b { guard x >= 10; reset x := 0; label done; }
      init a { x in [0, 1]; }
      scenario { until 20; u = step(0: 0, 5: 1); }
      property r: reach x >= 5 within 10;
      property small: always x <= 10;
    }
    """)


@pytest.fixture(scope="module")
def probe(tmp_path_factory):
    path = tmp_path_factory.mktemp("probe") / "probe.ha"
    path.write_text(PROBE)
    return str(path)


@pytest.mark.parametrize("model", [os.path.join(SPEC, "thermostat.ha"),
                                   os.path.join(SPEC, "hand.ha"),
                                   os.path.join(SPEC, "controlled_hand.ha"),
                                   os.path.join(BENCH, "fischer_2_unsafe.ha"),
                                   os.path.join(BENCH, "water_tank.ha")])
def test_info(model):
    assert_valid("info.schema.json", run("info", model, "--json"))


def test_info_of_the_probe(probe):
    info = run("info", probe, "--json")
    assert_valid("info.schema.json", info)
    component = info["components"][0]
    assert component["unreachable_modes"] == ["lost"] and info["warnings"]
    assert component["initial_states"][0]["values"]["x"] == [0.0, 1.0]
    assert info["properties"][0]["within"] == 10.0


@pytest.mark.parametrize("args", [
    [os.path.join(SPEC, "thermostat.ha")],
    [os.path.join(SPEC, "bouncing_ball.ha")],
    [os.path.join(SPEC, "bouncing_ball.ha"), "--set", "v_rest=0"],  # Zeno: exit 5
    [os.path.join(SPEC, "hand.ha")],                                  # a shared input
    [os.path.join(SPEC, "controlled_hand.ha")],                       # seven components
    [os.path.join(BENCH, "fischer_2_unsafe.ha"), "--until", "10"],    # no event
])
def test_simulate(args):
    report = run("simulate", *args, "--json", codes=(0, 5))
    assert_valid("simulate.schema.json", report)
    assert report["events"] or "fischer_2_unsafe.ha" in args[0]
    if "v_rest=0" in args:
        assert report["status"] == "zeno" and report["zeno"]["cycle"] == ["bounce"]
    if "controlled_hand.ha" in args[0]:
        assert report["final"]["mode"].count("|") == 6


def test_simulate_of_the_probe(probe):
    assert_valid("simulate.schema.json", run("simulate", probe, "--json"))


def test_check_with_violated_traces():
    report = run("check", os.path.join(BENCH, "fischer_2_unsafe.ha"), "--json", codes=(6,))
    assert_valid("check.schema.json", report)
    traces = [p["trace"] for p in report["properties"] if p["verdict"] == "violated"]
    assert traces and all(len(e["transitions"]) >= 1 for t in traces for e in t["events"])
    assert any("|" in t["state"]["mode"] for t in traces)


def test_check_of_the_finger_with_modes():
    # A small budget and depth keep this to a few seconds: some verdicts stay unknown.
    report = run("check", os.path.join(SPEC, "finger.ha"), "--property", "can_close_fully",
                 "--modes", "--depth", "6", "--budget", "4", "--json", codes=(0, 7))
    assert_valid("check.schema.json", report)
    assert len(report["modes"]) == 31
    assert any("trace" in m for m in report["modes"])
    assert set(report["modes"][0]["discrete"]) == {"c1", "c2", "c3", "l1", "l2", "l3"}


def test_check_of_the_tank(tmp_path):
    # The tank of test_hybrid.py: violated (with an input in the trace), reachable, proved.
    path = tmp_path / "tank.ha"
    path.write_text(TANK)
    report = run("check", str(path), "--json", codes=(6,))
    assert_valid("check.schema.json", report)
    assert {p["verdict"] for p in report["properties"]} == {"violated", "reachable", "proved"}
    report = run("check", str(path), "--method", "sample", "--runs", "20", "--json", codes=(6, 7))
    assert_valid("check.schema.json", report)


def test_check_of_the_probe_with_modes(probe):
    report = run("check", probe, "--modes", "--budget", "4", "--json", codes=(0, 6, 7))
    assert_valid("check.schema.json", report)
    assert [m["mode"] for m in report["modes"]] == ["a", "b", "lost"]
    # The bounded reach keeps its horizon, as info reports it.
    assert report["properties"][0]["within"] == 10.0 and "within" not in report["properties"][1]


@pytest.mark.parametrize("args", [
    ["--g", "200", "--gob1", "80"],
    ["--requests", "100,255,0"],
    ["--g", "255", "--object", "circle:0.06,0.08,0.01", "--simulate"],
    [],  # --g 255 by default
])
def test_finger(args):
    assert_valid("finger.schema.json", run("finger", *args, "--json"))


def test_finger_batch(tmp_path):
    batch = run("finger", "--g-range", "0:255:11", "--json")
    assert_valid("finger_batch.schema.json", batch)
    assert len(batch) == 11
    queries = tmp_path / "q.csv"
    queries.write_text("g\n0\n81.5\n255\n")
    assert_valid("finger_batch.schema.json",
                 run("finger", "--queries", str(queries), "--gob2", "150", "--json"))


@pytest.mark.parametrize("args", [
    ["--object", "circle:0,0.06,0.02", "--mode", "pinch"],
    ["--simulate"],
    ["--object", "circle:0,0.06,0.02", "--mode", "pinch", "--simulate"],
    ["--spread", "50"],  # the spread set directly: mode null
])
def test_hand(args):
    report = run("hand", *args, "--json")
    assert_valid("hand.schema.json", report)
    if "pinch" in args:
        assert ["A", "B"] in [t["fingers"] for t in report["finger_touches"]]


@pytest.fixture(scope="module")
def diagnosis():
    return run("diagnose", os.path.join(SOURCE, "data", "finger_demo.csv"), "--json")


def test_diagnose(diagnosis):
    assert_valid("diagnose.schema.json", diagnosis)
    assert diagnosis["where"] is None
    # An unexplained cause gives `where` an object: the schema's other branch.
    unexplained = copy.deepcopy(diagnosis)
    unexplained.update(cause=["unexplained"], parameters={}, parameter_units={},
                       where={"joint": "theta3", "mode": "c100_l010", "direction": "closing",
                              "g_range": [180.0, 230.0], "mean_residual": 2.5, "excess": 3.0})
    assert_valid("diagnose.schema.json", unexplained)


def test_diagnose_model():
    # A trace of any model: the thermostat with a shifted threshold, named with a parameter.
    report = run("diagnose", os.path.join(SPEC, "thermostat_urgent.ha"),
                 os.path.join(SOURCE, "data", "thermostat_threshold.csv"), "--json")
    assert_valid("diagnose_model.schema.json", report)
    assert report["cause"] == ["switch_on.threshold"]
    # The other branches: unexplained with `where`, and a remainder.
    located = {"variable": "x", "mode": "on", "time_range": [1.0, 2.0], "mean_residual": 0.3,
               "excess": 4.0}
    other = copy.deepcopy(report)
    other.update(cause=["unexplained"], parameters={}, where=located, remainder=located)
    assert_valid("diagnose_model.schema.json", other)


def test_the_python_modules_dicts(tmp_path):
    # docs/python.md: the module's dicts are the command line's documents.
    hybrid = pytest.importorskip("hybrid")
    tank = tmp_path / "tank.ha"
    tank.write_text(TANK)
    assert_valid("check.schema.json", hybrid.load(tank).check())
    model = hybrid.load(os.path.join(SPEC, "thermostat.ha"))
    assert_valid("info.schema.json", model.info())
    run_ = model.simulate(until=30.0, inputs={"u": 10.0})
    for numpy_member in ("time", "states", "modes"):  # the trajectory, beyond the document
        del run_[numpy_member]
    assert_valid("simulate.schema.json", run_)
    assert_valid("hand.schema.json", hybrid.hand(objects=["circle:0,0.06,0.02"], mode="pinch"))


# ---------------------------------------------------------------------------------------------
# The schemas bite: edited outputs fail.

@pytest.fixture(scope="module")
def outputs():
    queries = ["finger", "--g", "200", "--gob1", "80", "--json"]
    return {
        "simulate": run("simulate", os.path.join(SPEC, "thermostat.ha"), "--json"),
        "check": run("check", os.path.join(BENCH, "fischer_2_unsafe.ha"), "--json", codes=(6,)),
        "info": run("info", os.path.join(SPEC, "thermostat.ha"), "--json"),
        "finger": run(*queries),
        "requests": run("finger", "--requests", "100,255,0", "--json"),
        "batch": run("finger", "--g-range", "0:255:3", "--json"),
        "hand": run("hand", "--object", "circle:0,0.06,0.02", "--mode", "pinch", "--json"),
    }


def edited(document, edit):
    document = copy.deepcopy(document)
    edit(document)
    return document


def rename(obj, old, new):
    obj[new] = obj.pop(old)


def first_trace(report):
    return next(p["trace"] for p in report["properties"] if "trace" in p)


MUTATIONS = {
    # simulate
    "simulate: an extra member": (
        "simulate", "simulate.schema.json", lambda d: d.update(extra=1)),
    "simulate: final.values renamed final.state": (
        "simulate", "simulate.schema.json", lambda d: rename(d["final"], "values", "state")),
    "simulate: final without its mode": (
        "simulate", "simulate.schema.json", lambda d: d["final"].pop("mode")),
    "simulate: transitions a string": (
        "simulate", "simulate.schema.json",
        lambda d: d["events"][0].update(transitions="+".join(d["events"][0]["transitions"]))),
    "simulate: an event with an extra member": (
        "simulate", "simulate.schema.json", lambda d: d["events"][0].update(modes_before="off")),
    "simulate: a value that is a string": (
        "simulate", "simulate.schema.json", lambda d: d["final"]["values"].update(x="21.9")),
    "simulate: an unknown status": (
        "simulate", "simulate.schema.json", lambda d: d.update(status="done")),
    # check
    "check: trace event transitions a string": (
        "check", "check.schema.json",
        lambda d: first_trace(d)["events"][0].update(transitions="L.set_1+P1.write")),
    "check: trace event with simulate's before": (
        "check", "check.schema.json", lambda d: first_trace(d)["events"][0].update(before={})),
    "check: trace state without values": (
        "check", "check.schema.json", lambda d: rename(first_trace(d)["state"], "values", "x")),
    "check: a never property proved reachable": (
        "check", "check.schema.json", lambda d: d["properties"][0].update(verdict="reachable")),
    "check: an extra member in a property": (
        "check", "check.schema.json", lambda d: d["properties"][0].update(horizon=3.0)),
    # info
    "info: an extra member in a mode": (
        "info", "info.schema.json", lambda d: d["components"][0]["modes"][0].update(initial=True)),
    "info: urgency not a keyword": (
        "info", "info.schema.json",
        lambda d: d["components"][0]["transitions"][0].update(urgency="eager")),
    # finger
    "finger: discrete renamed state": (
        "finger", "finger.schema.json", lambda d: rename(d, "discrete", "state")),
    "finger: a configuration member without g": (
        "finger", "finger.schema.json", lambda d: d.pop("g")),
    "finger: a discrete value out of its range": (
        "finger", "finger.schema.json", lambda d: d["discrete"].update(c1=2)),
    "finger: a motor position above 255": (
        "finger", "finger.schema.json", lambda d: d.update(g=300.0)),
    "finger: a contact by something unknown": (
        "finger", "finger.schema.json", lambda d: d["contacts"][0].update(by="gob")),
    "finger: a request with g": (
        "requests", "finger.schema.json", lambda d: d["requests"][0].update(g=100.0)),
    "finger batch: an extra member": (
        "batch", "finger_batch.schema.json", lambda d: d[0].update(discrete={})),
    # hand
    "hand: fingers a string": (
        "hand", "hand.schema.json",
        lambda d: d["finger_touches"][0].update(fingers="".join(d["finger_touches"][0]["fingers"]))),
    "hand: a finger with state": (
        "hand", "hand.schema.json", lambda d: rename(d["fingers"][0], "discrete", "state")),
    "hand: two fingers": (
        "hand", "hand.schema.json", lambda d: d["fingers"].pop()),
}


@pytest.mark.parametrize("mutation", sorted(MUTATIONS))
def test_edited_outputs_fail(outputs, mutation):
    output, schema, edit = MUTATIONS[mutation]
    assert_valid(schema, outputs[output])
    assert errors(schema, edited(outputs[output], edit)), mutation


def test_edited_diagnosis_fails(diagnosis):
    for edit in (lambda d: d.update(extra=1),
                 lambda d: d["noise_floor"].update(method="guess"),
                 lambda d: d["parameters"].update(friction=1.0),
                 lambda d: d["residuals"][0].update(direction="up"),
                 lambda d: d["data"].pop("runs")):
        assert errors("diagnose.schema.json", edited(diagnosis, edit))


# ---------------------------------------------------------------------------------------------
# docs/cli.md lists the members of every document as the schemas define them.

def schema_paths(name):
    """The members of schema `name` as docs/cli.md lists them: one line per path, `a.b` a
    member, `a[]` the elements of an array, `{NAME}` a member named after something of the model;
    then its type (`X | Y` either; enumerated values quoted), `(optional)` for a member that
    is not always there and `(with M)` for one there exactly when member M is."""
    lines = []

    def node_info(doc, node):
        """(types, literals, members, map, items) of a schema node, following $ref, allOf and
        anyOf; members: [(key, doc, schema, required, condition)]."""
        info = {"types": [], "literals": [], "members": [], "map": [], "items": []}

        def add(doc, node):
            if "$ref" in node:
                ref_doc, target = resolve(doc, node["$ref"])
                add(ref_doc, target)
            for branch in node.get("allOf", []):
                add(doc, branch)
            for branch in node.get("anyOf", []) + node.get("oneOf", []):
                add(doc, branch)
            types = node.get("type", [])
            for t in [types] if isinstance(types, str) else types:
                if t not in info["types"]:
                    info["types"].append(t)
            for value in node.get("enum", []) + ([node["const"]] if "const" in node else []):
                if value not in info["literals"]:
                    info["literals"].append(value)
            required = set(node.get("required", []))
            dependent = node.get("dependentSchemas", {})
            for key, member in node.get("properties", {}).items():
                info["members"].append((key, doc, member, key in required, None))
                if key in dependent:
                    sub = node_info(doc, dependent[key])
                    info["members"] += [(k, d, m, False, key) for k, d, m, _, _ in sub["members"]]
            if isinstance(node.get("additionalProperties"), dict):
                info["map"].append((doc, node["additionalProperties"]))
            if isinstance(node.get("items"), dict):
                info["items"].append((doc, node["items"]))
            for item in node.get("prefixItems", []):
                info["items"].append((doc, item))

        add(doc, node)
        return info

    def type_text(info):
        types = list(info["types"])
        for value in info["literals"]:
            kind = {str: "string", bool: "boolean", int: "integer", float: "number",
                    type(None): "null"}[type(value)]
            if kind not in types and not (kind == "integer" and "number" in types):
                types.append(json.dumps(value))
        return " | ".join(types)

    def walk(path, doc, node, note=""):
        info = node_info(doc, node)
        if path:
            lines.append(f"{path}: {type_text(info)}{note}")
        for key, member_doc, member, required, condition in info["members"]:
            member_note = "" if required else (f" (with {condition})" if condition
                                               else " (optional)")
            walk(f"{path}.{key}" if path else key, member_doc, member, member_note)
        if info["map"]:
            walk_many(f"{path}.{{NAME}}", info["map"])
        if info["items"]:
            walk_many(f"{path}[]", info["items"])

    def walk_many(path, nodes):
        if len(nodes) == 1:
            walk(path, *nodes[0])
            return
        # several item schemas (prefixItems): one line, their types joined
        infos = [node_info(doc, node) for doc, node in nodes]
        texts = []
        for info in infos:
            text = type_text(info)
            if text not in texts:
                texts.append(text)
        lines.append(f"{path}: {' | '.join(texts)}")

    walk("", name, SCHEMAS[name])
    return lines


def documented_paths(name):
    """The listing docs/cli.md gives for schema `name`: the first code block after the link to
    it."""
    with open(os.path.join(SOURCE, "docs", "cli.md")) as f:
        text = f.read()
    link = text.index(f"(schemas/{name})")
    block = re.compile(r"^```\n(.*?)^```", re.S | re.M).search(text, link)
    assert block, f"no listing after the link to {name}"
    return block.group(1).splitlines()


@pytest.mark.parametrize("name", DOCUMENTS)
def test_docs_list_the_schemas_members(name):
    assert documented_paths(name) == schema_paths(name)
