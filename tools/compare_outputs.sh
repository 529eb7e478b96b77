#!/usr/bin/env bash
# Compares two output folders of tools/main_job.sh (e.g. out/ of two commits), file by file and
# byte for byte, except the wall-clock fields ("seconds") of the JSON files. Used to show that a
# refactoring changes no result (docs/architecture.md).
#
# Usage: tools/compare_outputs.sh BEFORE AFTER
# check_finger_modes.json: its properties, its list of modes and every mode decided in both files
# (verdict and trace) must be equal; a mode may be "unknown" in one of them, because under a heavy
# machine load a --modes query can hit its wall-clock safety limit (docs/verification.md).
# Exits 1 if anything differs.
set -euo pipefail
[ $# -eq 2 ] || { sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
before=$1 after=$2
status=0
while IFS= read -r -d '' file; do
  rel=${file#"$before"/}
  other="$after/$rel"
  if [ ! -f "$other" ]; then
    echo "missing in $after: $rel"; status=1; continue
  fi
  case "$rel" in
    check_finger_modes.json)
      if python3 - "$file" "$other" <<'PY'; then :; else status=1; fi
import json, sys
def timeless(x):
    if isinstance(x, dict):
        return {k: timeless(v) for k, v in x.items() if k != "seconds"}
    return [timeless(v) for v in x] if isinstance(x, list) else x
a, b = (timeless(json.load(open(f))) for f in sys.argv[1:3])
ok = a["properties"] == b["properties"] and [m["mode"] for m in a["modes"]] == [m["mode"] for m in b["modes"]]
known = [(x, y) for x, y in zip(a["modes"], b["modes"]) if "unknown" not in (x["verdict"], y["verdict"])]
ok = ok and all(x == y for x, y in known)
unknown = [sum(m["verdict"] == "unknown" for m in d["modes"]) for d in (a, b)]
print(("same" if ok else "differs") + ": check_finger_modes.json (properties, modes, and the "
      f"{len(known)} modes decided in both; unknown: {unknown[0]} vs {unknown[1]})")
sys.exit(0 if ok else 1)
PY
      ;;
    *.json)
      if diff -q -I '"seconds"' "$file" "$other" >/dev/null; then echo "same: $rel"; else
        echo "differs: $rel"; status=1; fi ;;
    *)
      if cmp -s "$file" "$other"; then echo "same: $rel"; else echo "differs: $rel"; status=1; fi ;;
  esac
done < <(find "$before" -type f -print0 | sort -z)
while IFS= read -r -d '' file; do
  rel=${file#"$after"/}
  [ -f "$before/$rel" ] || { echo "new in $after: $rel"; status=1; }
done < <(find "$after" -type f -print0 | sort -z)
exit "$status"
