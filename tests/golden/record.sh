#!/usr/bin/env bash
# Records tests/golden/NAME.csv: the physics columns of stats.csv (all but ms_*) of scenes/NAME.json
# run for as many steps as the file holds rows (or STEPS), with the switches of NAME.set
# (tests/cli/test_same_results.cpp).
# Usage: tests/golden/record.sh BINARY NAME [STEPS]   (run from the repository root)
set -euo pipefail
bin=$1 name=$2
golden="tests/golden/$name.csv"
steps=${3:-$(($(wc -l <"$golden") - 1))}
# The switches of NAME.set, or, for a new scene, those the scene gives (the defaults otherwise).
if [[ ! -f "tests/golden/$name.set" ]]; then
  python3 - "scenes/$name.json" >"tests/golden/$name.set" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
for section, key in [("boundary", "correction"), ("coupling", "two_way"), ("coupling", "correction"),
                     ("coupling", "predict_solids"), ("coupling", "strong"), ("coupling", "surface_inset")]:
    value = scene.get(section, {}).get(key, True)
    print(f"{section}.{key}={'true' if value else 'false'}")
PY
fi
sets=$(sed 's/^/--set /' "tests/golden/$name.set" | tr '\n' ' ')
out=$(mktemp -d)
# shellcheck disable=SC2086
"$bin" run "scenes/$name.json" --steps "$steps" --set 'output.formats=[]' --threads 2 --quiet --out "$out" $sets
python3 - "$out/stats.csv" "$golden" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
keep = [i for i, c in enumerate(rows[0]) if not c.startswith("ms_")]
with open(sys.argv[2], "w") as f:
    for r in rows:
        f.write(",".join(r[i] for i in keep) + "\n")
PY
rm -rf "$out"
echo "recorded $golden ($steps steps)"
