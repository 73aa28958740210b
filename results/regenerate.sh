#!/usr/bin/env bash
# Regenerates the committed evidence in results/: the convergence study of
# every scenario family (results/converge/<scenario>/) and the benchmark
# (results/bench.md). Run from the repository root:
#
#     bash results/regenerate.sh            # everything (about 10-20 minutes)
#     bash results/regenerate.sh converge   # the convergence studies only
#     bash results/regenerate.sh bench      # the benchmark only
#     bash results/regenerate.sh converge-direct  # the direct approach's studies only
#     bash results/regenerate.sh converge-off  # results/converge-off/: the studies
#                                           # with the part moved off the lattice
#     bash results/regenerate.sh converge-surface  # results/converge-surface/ and
#     bash results/regenerate.sh converge-surface-off  # converge-surface-off/:
#                                           # the same under --level surface, to
#                                           # 1 mm (about 12 minutes a part)
#     bash results/regenerate.sh converge-surface bump tilted-wave  # (any
#                                           # converge mode) those parts alone
#     bash results/regenerate.sh converge-table  # results/README.md's convergence
#                                           # table alone, from the studies' files
#     bash results/regenerate.sh ab REV     # results/ab.md: this tree against
#                                           # the commit REV, end to end, in one run
#     bash results/regenerate.sh strip      # results/converge-strip/: the wave's
#                                           # study over a whole strip of 21 start
#                                           # rows, every start (about 2 minutes)
#     bash results/regenerate.sh strip-console  # results/converge-strip/console-row/:
#                                           # every start of one console start row
#                                           # (z = 300 mm), all 61 angles at 1.24 mm
#                                           # (about 9 minutes)
#     bash results/regenerate.sh strip-console-20  # results/converge-strip/
#                                           # console-20-rows/: every start of 20
#                                           # console start rows, all 61 angles
#                                           # at 1.24 mm (about 1.5 to 2 hours)
#     bash results/regenerate.sh strip-console-20-table  # its README's table
#                                           # alone, from the angles' verify.json
#     bash results/regenerate.sh pitch      # results/pitch.md: the bundled console
#                                           # at 0.5 mm (61 angles) and 0.25 mm
#                                           # (3 angles), about 6 minutes
#
# Every study uses the same settings so they can be compared: pitches 4, 2,
# 1 and 0.5 mm (0.25 mm too on the wave and the depression), angles -30, 0
# and 30 degrees, the default starts (ten seeded patches of 3 rows of 5, seed 1:
# places that measure an area; scattered starts are INCONCLUSIVE), tolerance 1 mm, SPEC's default
# strike rule (deflection 0.5 degrees, e0 1e-6 mm) and tie band.
set -euo pipefail
cd "$(dirname "$0")/.."
what="${1:-all}"
# Scenario families named after the mode (converge modes only): those alone.
only=("${@:2}")
cargo build --release --quiet
bin=target/release/kneeform

# One convergence study per scenario family into results/DIR/<scenario>/:
# `studies DIR OPTION...`, the options (the level, the frame) passed on.
studies() {
  local dir=$1
  shift
  mkdir -p "results/$dir"
  for file in scenarios/*.toml; do
    name=$(basename "$file" .toml)
    [[ ${#only[@]} -gt 0 && " ${only[*]} " != *" $name "* ]] && continue
    pitches=4,2,1,0.5
    # The wave and the depression also at 0.25 mm (SPEC's smooth parts,
    # cheap enough); the console stops at 0.5 mm (12 million nodes).
    [[ "$name" == wave || "$name" == depression ]] && pitches=4,2,1,0.5,0.25
    # The surface level stops at 1 mm: its whole analysis at 0.5 mm (the
    # area a study's misses are measured to) takes over an hour a study on
    # 2 cores (the bump's 1 mm about 9 minutes, each halving about 8x).
    [[ "$dir" == converge-surface* ]] && pitches=4,2,1
    echo "== $dir/$name"
    # A study refuses an existing --out (issue 41): the committed one is
    # this script's own, in git.
    rm -rf "results/$dir/$name"
    "$bin" converge "$file" "$@" --pitches "$pitches" --angles=-30,0,30 --seed 1 \
      --tolerance 1 --out "results/$dir/$name"
  done
}

# The part moved off the grid's lattice by a sub-pitch translation,
# (0.37, 0, 0.61) mm: the scenarios' features sit on multiples of every
# pitch studied, which flatters any grid; moved off it they sit on none.
off=(--frame @results/gate/off-lattice.txt)

if [[ "$what" == all || "$what" == converge ]]; then
  studies converge
fi
if [[ "$what" == all || "$what" == converge-off ]]; then
  studies converge-off "${off[@]}"
fi
# The surface level (SPEC v4) on and off the lattice: about a hundred times
# the node level's engine time, so not part of "all".
if [[ "$what" == converge-surface ]]; then
  studies converge-surface --level surface
fi
if [[ "$what" == converge-surface-off ]]; then
  studies converge-surface-off --level surface "${off[@]}"
fi

if [[ "$what" == all || "$what" == converge* ]]; then
  # The tables of results/README.md's "What converges, and at what order",
  # one per study folder (the node level on and off the lattice, the
  # surface level on and off it), one row per scenario, from each study's
  # converge.csv and converge.json: each written in place between its
  # markers `<!-- table: DIR -->` and `<!-- end table -->`; a scenario whose
  # study is not there reads "not run".
  python3 - results <<'PY'
import csv, json, os, sys
root = sys.argv[1]
names = {"depression": "depression, Fig. 2b", "wavy-ridge": "wavy ridge, Fig. 6",
         "thin-rib": "thin rib 0.6 mm", "console": "**console**"}
order = ["flat-wall", "groove", "ramp", "wave", "growing-wave", "depression", "step",
         "pocket-behind-ridge", "tilted-wave", "wavy-ridge", "bump", "angled-features",
         "switch-boss", "thin-rib", "console"]
metrics = [("miss_distance_decided", True), ("first_contact_error_decided", True),
           ("area_miss_distance_decided", True), ("false_alarm_distance_decided", True),
           ("area_false_alarm_distance_decided", True), ("push_error_decided", True),
           ("level_error_bound", False), ("area_distance_blind", False)]
def table(folder):
    rows = ["| part | finest pitch | miss | first contact | area miss | false alarm | area false alarm "
            "| push | level-error bound | blind area distance | outcome at the finest pitch | coarsest PASS at 1 mm |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for name in order:
        label = names.get(name, name.replace('-', ' '))
        d = os.path.join(root, folder, name)
        if not os.path.exists(os.path.join(d, "converge.json")):
            rows.append(f"| {label} | not run |" + " |" * 10)
            continue
        c = json.load(open(os.path.join(d, "converge.json")))
        finest = min(c["pitches_mm"])
        table = {(float(r["pitch_mm"]), r["metric"]): r for r in csv.DictReader(open(os.path.join(d, "converge.csv")))}
        verdict = next(v for v in c["verdicts"] if v["pitch_mm"] == finest)
        cells = []
        for metric, fitted in metrics:
            v = float(table[(finest, metric)]["max"])
            cell = "0" if v == 0 else f"{v:.2f}"
            fit = c["fits"].get(metric) if fitted else None
            if fit and v > 1e-6:
                cell += f" ({fit['alpha']:.2f})"
            named = [f["mechanism"] for f in verdict["failures"] if f["metric"] == metric and f["value"] is not None and abs(f["value"] - v) < 1e-9]
            if named:
                cell += " " + named[0]
            cells.append(cell)
        rec = c["recommended_pitch_mm"]
        rows.append(f"| {label} | {finest:g} | " + " | ".join(cells)
                    + f" | {verdict['outcome']} | {'none' if rec is None else f'{rec:g} mm'} |")
    return rows
readme = os.path.join(root, "README.md")
lines = open(readme).read().split("\n")
for folder in ["converge", "converge-off", "converge-surface", "converge-surface-off"]:
    marker = f"<!-- table: {folder} -->"
    if marker not in lines:
        continue
    first = lines.index(marker) + 1
    last = next(n for n in range(first, len(lines)) if lines[n] == "<!-- end table -->")
    lines[first:last] = [""] + table(folder) + [""]
open(readme, "w").write("\n".join(lines))
PY
fi

if [[ "$what" == all || "$what" == converge || "$what" == converge-direct ]]; then
  # The direct approach (issue 12) against its exact oracle on the smooth
  # parts, turned by --frame -y,x,z so that their surface faces +x, towards
  # the knee-form coming from +x. Same pitches, angles, starts and seed.
  for name in tilted-wave wave ramp; do
    echo "== $name (direct)"
    rm -rf "results/converge-direct/$name"
    "$bin" converge "scenarios/$name.toml" --frame=-y,x,z --approach direct \
      --pitches 4,2,1,0.5 --angles=-30,0,30 --starts 60 --seed 1 \
      --tolerance 1 --out "results/converge-direct/$name"
  done
fi

if [[ "$what" == all || "$what" == strip ]]; then
  # SPEC's area distance over every start of a strip (issue 26, item 3):
  # the wave's 21 start rows z in [-40, 40] mm at the coarsest pitch, all
  # 4,851 of their starts, the same pitches and angles as the sampled study.
  "$bin" converge scenarios/wave.toml --pitches 4,2,1,0.5 --angles=-30,0,30 \
    --starts strip:-40:40 --tolerance 1 --out results/converge-strip/wave
fi

if [[ "$what" == strip-console ]]; then
  # SPEC's area distance over every start of one start row of the console
  # (z = 300 mm: 1,467 starts), at all 61 angles and the paper's pitch
  # (issue 26, item 3, one row of the twenty it asks for). The angles run
  # in four groups, each its own verification, so that one group's exact
  # traces (about 7 GiB) fit in memory; the area distance is per angle, so
  # the groups' figures are the whole row's. Exit 1 (a failing verdict) is
  # a result here, not an error.
  out=results/converge-strip/console-row
  for group in -30:-16 -15:-1 0:14 15:30; do
    echo "== console row, angles $group"
    "$bin" verify scenarios/console_side.stl --starts strip:299.5:300.5 \
      --angles="$group:1" --out "$out/angles_${group/:/_to_}" || [[ $? == 1 ]]
  done
fi

if [[ "$what" == strip-console-20 ]]; then
  # Every start of 20 start rows of the console (z = 288.92 to 312.48 mm,
  # about 29,000 starts, the row above in the middle), all 61 angles and
  # the paper's pitch: the rows' exact and grid traces chained (issue
  # 26). One verification per angle, so that one angle's traces (about
  # 10 GiB) fit in memory. Exit 1 (a failing verdict) is a result here.
  out=results/converge-strip/console-20-rows
  for angle in $(seq -30 30); do
    echo "== console, 20 rows, angle $angle"
    "$bin" verify scenarios/console_side.stl --starts strip:288.5:312.6 \
      --angles="$angle" --out "$out/angle_$angle" || [[ $? == 1 ]]
  done
fi

if [[ "$what" == strip-console-20 || "$what" == strip-console-20-table ]]; then
  # The table of console-20-rows/README.md, one row per angle, from each
  # angle's verify.json: written in place of the README's table (the
  # lines from its header row to the 30 degrees row).
  python3 - results/converge-strip/console-20-rows <<'PY'
import json, os, sys
out = sys.argv[1]

def named(d, metric, value):
    """The mechanism verify.json names for `metric` at `value`, or ''
    (an infinite value is null in verify.json)."""
    for f in d["failures"]:
        same = f["value"] == value if None in (f["value"], value) else abs(f["value"] - value) < 1e-9
        if f["metric"] == metric and same:
            return f" ({f['mechanism']})"
    return ""

def mm(v):
    return "inf" if v is None else f"{v:.3f}"

rows = ["| angle (deg) | verdict | decided area miss (mm) | decided area false alarm (mm) "
        "| decided miss per start (max, p95; mm) | oracle (s) | comparison (s) |",
        "| --- | --- | --- | --- | --- | --- | --- |"]
for angle in range(-30, 31):
    d = json.load(open(os.path.join(out, f"angle_{angle}", "verify.json")))
    m, t = d["metrics"], d["timings"]
    am = m["area_miss_distance_decided"]["max"]
    af = m["area_false_alarm_distance_decided"]["max"]
    pm = m["miss_distance_decided"]
    rows.append(
        f"| {angle} | {'PASS' if d['pass'] else 'FAIL'} "
        f"| {mm(am)}{named(d, 'area_miss_distance_decided', am)} "
        f"| {mm(af)}{named(d, 'area_false_alarm_distance_decided', af)} "
        f"| {mm(pm['max'])}{named(d, 'miss_distance_decided', pm['max'])}, {mm(pm['p95'])} "
        f"| {t['oracle_s']:.1f} | {t['grid_s']:.1f} |")
readme = os.path.join(out, "README.md")
lines = open(readme).read().split("\n")
first = next(n for n, l in enumerate(lines) if l.startswith("| angle (deg) |"))
last = next(n for n, l in enumerate(lines) if l.startswith("| 30 |"))
lines[first:last + 1] = rows
open(readme, "w").write("\n".join(lines))
PY
fi

if [[ "$what" == all || "$what" == bench ]]; then
  "$bin" bench --runs 5 --markdown results/bench.md
  # One binary's figures under the load of the moment; a change's ratio
  # needs both binaries in one run.
  printf '\n%s\n' "Before and after a change, both binaries alternating in one run: [ab.md](ab.md) (\`bash results/regenerate.sh ab REV\`)." >> results/bench.md
fi

# The before/after of a change, end to end and measured in one run (the
# machine is shared: the two binaries alternate, so both see the same load):
# the README's command on the bundled console side, its wall time at 2
# threads (median of 3) and its peak RSS at 1, 2 and 16 threads.
if [[ "$what" == ab ]]; then
  rev="${2:?usage: regenerate.sh ab REV}"
  work=$(mktemp -d)
  trap 'git worktree remove --force "$work/base" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
  git worktree add --detach -q "$work/base" "$rev"
  (cd "$work/base" && CARGO_TARGET_DIR="$OLDPWD/target/ab-base" cargo build --release --quiet --bin kneeform)
  cp target/ab-base/release/kneeform "$work/before"
  cp "$bin" "$work/after"
  part=scenarios/console_side.stl
  # One run: prints "wall_s peak_mib write_s output_mib". The wall time is
  # the command's, start to exit (summary.json's total_s leaves out the
  # process's start and end, and before 2026-11-24 the blind spots too).
  measure() {
    rm -rf "$work/out"
    local t0 t1
    t0=$(date +%s.%N)
    "$work/$1" analyze "$part" --out "$work/out" --threads "$2" >/dev/null 2>&1
    t1=$(date +%s.%N)
    python3 - "$work/out" "$t0" "$t1" <<'PY'
import json, os, sys
d = sys.argv[1]
s = json.load(open(os.path.join(d, "summary.json")))
size = sum(os.path.getsize(os.path.join(d, f)) for f in os.listdir(d))
wall = float(sys.argv[3]) - float(sys.argv[2])
print(f"{wall:.2f} {s['peak_rss_mib']:.0f} {s['timings']['write_s']:.2f} {size / 2**20:.1f}")
PY
  }
  {
    echo "# Before and after, measured in one run"
    echo
    echo "\`bash results/regenerate.sh ab $rev\` on $(date -u +%Y-%m-%d), $(nproc) CPUs"
    echo "($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)), load average at the start"
    echo "$(cut -d' ' -f1-3 /proc/loadavg). Before: $(git rev-parse --short "$rev"); after: this tree"
    echo "($(git rev-parse --short HEAD)$(git diff --quiet || echo ', with changes')). Part: \`$part\`, the README's"
    echo "command at default settings (1.24 mm, 61 angles). The binaries alternate."
    echo
    echo "| threads | before: wall s | after: wall s | before: peak MiB | after: peak MiB | before: write s | after: write s | before: outputs MiB | after: outputs MiB |"
    echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    for t in 2 2 2 1 16; do
      b=($(measure before "$t")); a=($(measure after "$t"))
      echo "| $t | ${b[0]} | ${a[0]} | ${b[1]} | ${a[1]} | ${b[2]} | ${a[2]} | ${b[3]} | ${a[3]} |"
    done
  } > results/ab.md
  cat results/ab.md
fi

# The fine pitches on the bundled console (`scenarios/console.toml`, 600 x
# 300 mm class): 0.5 mm and 0.25 mm with SPEC's 61 angles (about 4 minutes
# in all here, 5 GiB at the finer): time by stage, peak RSS against the
# memory estimate.
if [[ "$what" == pitch ]]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  {
    echo "# Fine pitches on the bundled console"
    echo
    echo "\`bash results/regenerate.sh pitch\` on $(date -u +%Y-%m-%d), $(nproc) CPUs"
    echo "($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)), load average at the start"
    echo "$(cut -d' ' -f1-3 /proc/loadavg); $(git rev-parse --short HEAD). Part: \`scenarios/console.toml\`,"
    echo "default settings otherwise (2 threads)."
    echo
    echo "| pitch mm | angles | grid | push+slide s | per angle s | total s | write s | peak MiB | estimate MiB |"
    echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    for run in "0.5 -30:30:1" "0.25 -30:30:1"; do
      set -- $run
      rm -rf "$work/out"
      "$bin" analyze scenarios/console.toml --pitch "$1" --angles="$2" --threads 2 \
        --out "$work/out" >/dev/null 2>&1
      python3 - "$work/out/summary.json" "$1" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
t = s["timings"]
n = len(s["angles_deg"])
g = s["grid_size"]
print(f"| {sys.argv[2]} | {n} | {g[0]} x {g[1]} | {t['push_slide_s']:.1f} | "
      f"{t['push_slide_s'] / n:.2f} | {t['total_s']:.1f} | {t['write_s']:.1f} | "
      f"{s['peak_rss_mib']:.0f} | {s['memory_estimate_mib']:.0f} |")
PY
    done
  } > results/pitch.md
  cat results/pitch.md
fi
