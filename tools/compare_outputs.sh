#!/usr/bin/env bash
# Compares two output folders of tools/main_job.sh (e.g. out/ of two commits), file by file and
# byte for byte, except the wall-clock fields ("seconds") of the JSON files. Used to show that a
# refactoring changes no result (docs/architecture.md).
#
# Usage: tools/compare_outputs.sh BEFORE AFTER
# Every file must be equal, check_finger_modes.json included: the prover's safety net counts CPU
# time, so the machine's load does not change a verdict (docs/verification.md). Exits 1 if
# anything differs.
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
