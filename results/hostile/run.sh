#!/usr/bin/env bash
# Issue 41's hostile classes, run again on small parts: each case is one
# command a hostile or careless user could type, and what kneeform must do.
#
#   results/hostile/run.sh [KNEEFORM] > counts.md   (a few minutes; the
#   full and read-only disk classes need root, to mount a small tmpfs)
#
# "Held" is what the issue demands: a refusal is exit 2, one line on
# stderr ("kneeform: error: ...", short), before any work, leaving the
# case's folder exactly as it was (no .lock, .partial-*, .tmp-*, no half
# result, nothing reused or replaced); an accepted case exits 0, 1 or 3
# and leaves no debris. Cases that do not hold are listed on stderr.
set -u
K=$(realpath "${1:-target/release/kneeform}")
W=$(mktemp -d /tmp/kneeform-hostile-XXXXXX)
trap 'umount "$W/full" "$W/ro" 2>/dev/null; rm -rf "$W"' EXIT
declare -A TRIED HELD
CLASSES=()
N=0

note_class() {
    [[ -v "TRIED[$1]" ]] || { CLASSES+=("$1"); TRIED[$1]=0; HELD[$1]=0; }
}

# A fresh folder for the next case (the current directory).
fresh() { N=$((N + 1)); D="$W/c$N"; mkdir -p "$D"; cd "$D" || exit 1; }

# Every file and folder of the case, with the files' digests.
snap() { find . \( -type f -exec sha256sum {} + \) -o \( -type d -print \) 2>/dev/null | sort; }

# Whether DIR holds exactly the files its kneeform-run.json records, each
# with its recorded SHA-256.
whole() {
    python3 - "$1" <<'EOF'
import hashlib, json, os, sys
d = sys.argv[1]
files = json.load(open(os.path.join(d, "kneeform-run.json")))["files"]
held = {f for f in os.listdir(d) if f != "kneeform-run.json"}
ok = held == set(files) and all(
    hashlib.sha256(open(os.path.join(d, f), "rb").read()).hexdigest() == r["sha256"]
    for f, r in files.items())
sys.exit(0 if ok else 1)
EOF
}

debris() { find . -name '*.lock' -o -name '*.partial-*' -o -name '*.tmp-*' 2>/dev/null | head -3; }

record() { # CLASS DESC HELD(0/1) WHY
    note_class "$1"
    TRIED[$1]=$((TRIED[$1] + 1))
    if [[ $3 == 1 ]]; then
        HELD[$1]=$((HELD[$1] + 1))
    else
        echo "NOT HELD [$1] $2: $4" >&2
    fi
}

# fails CLASS DESC CMD...: exit 2, its last line the error, the folder
# unchanged, no debris (what a full disk allows: it is met part way).
fails() {
    local class=$1 desc=$2
    shift 2
    local before after rc
    before=$(snap)
    timeout 300 "$@" >/dev/null 2>"$W/err" </dev/null
    rc=$?
    after=$(snap)
    local why=""
    [[ $rc == 2 ]] || why="exit $rc"
    [[ $(tail -1 "$W/err") == "kneeform: error: "* ]] || why="$why; the last line is no error"
    grep -qE 'panicked|RUST_BACKTRACE|memory allocation' "$W/err" && why="$why; a panic"
    [[ $before == "$after" ]] || why="$why; the folder changed"
    [[ -z $(debris) ]] || why="$why; debris $(debris)"
    record "$class" "$desc" "$([[ -z $why ]] && echo 1 || echo 0)" "$why: $(tail -c 200 "$W/err")"
}

# refuse CLASS DESC CMD...: exit 2, one short line, the folder unchanged.
refuse() {
    local class=$1 desc=$2
    shift 2
    local before after rc err
    before=$(snap)
    timeout 120 "$@" >/dev/null 2>"$W/err" </dev/null
    rc=$?
    err=$(cat "$W/err")
    after=$(snap)
    local why=""
    [[ $rc == 2 ]] || why="exit $rc"
    [[ $(wc -l <"$W/err") == 1 ]] || why="$why; $(wc -l <"$W/err") lines"
    [[ $err == "kneeform: error: "* ]] || why="$why; not an error line"
    ((${#err} < 400)) || why="$why; ${#err} characters"
    [[ $before == "$after" ]] || why="$why; the folder changed"
    [[ -z $(debris) ]] || why="$why; debris $(debris)"
    record "$class" "$desc" "$([[ -z $why ]] && echo 1 || echo 0)" "$why: ${err:0:200}"
}

# accept CLASS DESC CMD...: exit 0, 1 or 3, no debris, no panic.
accept() {
    local class=$1 desc=$2
    shift 2
    local rc
    timeout 300 "$@" >/dev/null 2>"$W/err" </dev/null
    rc=$?
    local why=""
    [[ $rc == 0 || $rc == 1 || $rc == 3 ]] || why="exit $rc"
    grep -qE 'panicked|RUST_BACKTRACE|memory allocation' "$W/err" && why="$why; a panic"
    [[ -z $(debris) ]] || why="$why; debris $(debris)"
    record "$class" "$desc" "$([[ -z $why ]] && echo 1 || echo 0)" "$why: $(head -c 200 "$W/err")"
}

P="$W/parts"
mkdir -p "$P"
"$K" scenario bump --out "$P/bump.stl" >/dev/null 2>&1
"$K" scenario wave --out "$P/wave.stl" >/dev/null 2>&1
BUMP="$P/bump.stl"
FAST=(--pitch 8 --angles=-30,0,30 --threads 2)
ONE=(--pitch 8 --angles=0 --threads 2)
# Finished results to refuse, merge and report.
mkdir -p "$W/runs"
cd "$W/runs" || exit 1
"$K" analyze "$BUMP" "${FAST[@]}" --out a >/dev/null 2>&1
"$K" analyze "$BUMP" "${FAST[@]}" --no-check --out anocheck >/dev/null 2>&1
"$K" verify "$BUMP" "${ONE[@]}" --starts 4 --out v >/dev/null 2>&1
"$K" converge "$BUMP" --pitches 16,8 --angles=0 --threads 2 --starts 4 --out c >/dev/null 2>&1
for k in 1 2; do
    "$K" analyze "$BUMP" "${FAST[@]}" --shard $k/2 --out as$k >/dev/null 2>&1
    "$K" analyze "$BUMP" "${FAST[@]}" --shard $k/2 --no-check --out an$k >/dev/null 2>&1
    "$K" verify "$BUMP" "${ONE[@]}" --starts 6 --shard $k/2 --out vs$k >/dev/null 2>&1
    "$K" analyze "$BUMP" --pitch 4 --angles=-30,0,30 --threads 2 --shard $k/2 --out ap$k >/dev/null 2>&1
done
R="$W/runs"

# --- start selections ------------------------------------------------------
for s in -1 0 nonsense strip:1e-320:1e-320 strip:5:1 strip:nan:1 \
    runs:0:3 runs:3:0 runs:1e20:3 patches:0:5:3 patches:1:0:3 patches:1:5:0 \
    patches:1:5:3:9 patches:-1:5:3 patches:1e9:5:3 '' all:2 runs:3 4.5 1e30; do
    fresh
    refuse starts "--starts '$s'" "$K" verify "$BUMP" "${ONE[@]}" --starts "$s" --out o
done
for s in 4 runs:2:3 patches:2:3:3 strip:0:8 strip:0:0 strip:-1e300:1e300; do
    fresh
    accept starts "--starts $s" "$K" verify "$BUMP" "${ONE[@]}" --starts "$s" --out o
done
for s in -1 0 nonsense strip:1e-320:1e-320 runs:0:3; do
    fresh
    refuse starts "converge --starts '$s'" "$K" converge "$BUMP" --pitches 16,8 --angles=0 --threads 2 --starts "$s" --out o
done

# --- shards and merge -------------------------------------------------------
for s in 0/2 3/2 1/0 a/b 1/ /2 -1/2 1/1e9 2/1 1.5/2 1/100000; do
    fresh
    refuse shards "analyze --shard $s" "$K" analyze "$BUMP" "${FAST[@]}" --shard "$s" --out o
    fresh
    refuse shards "verify --shard $s" "$K" verify "$BUMP" "${ONE[@]}" --starts 4 --shard "$s" --out o
done
fresh
refuse shards "merge of no shard" "$K" merge --out o
fresh
refuse shards "merge of one of two shards" "$K" merge "$R/as1" --out o
fresh
refuse shards "merge of a shard twice" "$K" merge "$R/as1" "$R/as1" --out o
fresh
refuse shards "merge of shards differing in --no-check (a1 c2)" "$K" merge "$R/as1" "$R/an2" --out o
fresh
refuse shards "merge of shards differing in --no-check (c1 a2)" "$K" merge "$R/an1" "$R/as2" --out o
fresh
refuse shards "merge of shards of two pitches" "$K" merge "$R/as1" "$R/ap2" --out o
fresh
refuse shards "merge of an analysis and a verify shard" "$K" merge "$R/as1" "$R/vs2" --out o
fresh
refuse shards "merge of a finished run" "$K" merge "$R/a" "$R/as2" --out o
for what in shard.json shard.bin; do
    for damage in truncate garbage empty fifo dir; do
        fresh
        cp -r "$R/as1" s1
        case $damage in
        truncate) head -c 100 "$R/as1/$what" >"s1/$what" ;;
        garbage) echo '{"not": "a shard"}' >"s1/$what" ;;
        empty) : >"s1/$what" ;;
        fifo) rm "s1/$what" && mkfifo "s1/$what" ;;
        dir) rm "s1/$what" && mkdir "s1/$what" ;;
        esac
        refuse shards "merge with $what $damage" "$K" merge s1 "$R/as2" --out o
    done
done
fresh
mkdir o && echo mine >o/keep
refuse shards "merge into a user's folder" "$K" merge "$R/as1" "$R/as2" --out o
fresh
mkdir o && echo mine >o/keep
refuse shards "merge into a user's folder with --force" "$K" merge "$R/as1" "$R/as2" --out o --force
fresh
cp -r "$R/v" o
refuse shards "merge of analysis shards into a verify folder, no --force" "$K" merge "$R/as1" "$R/as2" --out o
fresh
refuse shards "merge --out one of its shards" "$K" merge "$R/as1" "$R/as2" --out "$R/as1" --force
fresh
accept shards "merge of two analysis shards" "$K" merge "$R/as1" "$R/as2" --out o
if [[ $(zcat o/composite.csv.gz; cat o/zones.csv o/blind_spots.csv) == "$(zcat "$R/a/composite.csv.gz"; cat "$R/a/zones.csv" "$R/a/blind_spots.csv")" ]]; then
    record shards "sharded == unsharded (diff)" 1 ""
else
    record shards "sharded == unsharded (diff)" 0 "differs"
fi
fresh
accept shards "merge of two verify shards" "$K" merge "$R/vs1" "$R/vs2" --out o

# --- report -----------------------------------------------------------------
fresh
refuse report "report of a missing run" "$K" report nope --out r.html
fresh
refuse report "report of a verify folder as the run" "$K" report "$R/v" --out r.html
fresh
echo keep >r.html
refuse report "report onto an existing file" "$K" report "$R/a" --out r.html
fresh
cp -r "$R/a" a
refuse report "report --out the run's summary.json" "$K" report a --out a/summary.json --force
fresh
cp "$BUMP" part.stl
refuse report "report --out a part with --force" "$K" report "$R/a" --out part.stl --force
fresh
refuse report "report --part /dev/zero" "$K" report "$R/a" --part /dev/zero --out r.html
fresh
mkfifo pipe
refuse report "report --part a FIFO" "$K" report "$R/a" --part pipe --out r.html
fresh
cp -r "$R/a" a
sed -i 's/"composite_nodes": [0-9]*/"composite_nodes": 999999/' a/summary.json
refuse report "report of a tampered summary.json" "$K" report a --out r.html
fresh
cp -r "$R/v" v
awk -F, 'NR==2{$0=$0} {print}' v/verify.csv >/dev/null
python3 - v/verify.csv <<'EOF'
import sys
p = sys.argv[1]
rows = open(p).read().splitlines()
head = rows[0].split(",")
k = head.index("miss_distance_decided") if "miss_distance_decided" in head else 3
r = rows[1].split(","); r[k] = "999"; rows[1] = ",".join(r)
open(p, "w").write("\n".join(rows) + "\n")
EOF
refuse report "report of an edited verify.csv" "$K" report "$R/a" v --out r.html
fresh
cp -r "$R/v" v
for _ in $(seq 50); do tail -n +2 "$R/v/verify.csv"; done >>v/verify.csv
refuse report "report of a verify.csv with rows added" "$K" report "$R/a" v --out r.html
fresh
cp -r "$R/v" v
rm v/verify.csv && mkfifo v/verify.csv
refuse report "report of a FIFO verify.csv" "$K" report "$R/a" v --out r.html
fresh
cp -r "$R/v" v
echo '{' >v/verify.json
refuse report "report of a broken verify.json" "$K" report "$R/a" v --out r.html
fresh
refuse report "report of one verify folder 200 times" "$K" report "$R/a" $(for _ in $(seq 200); do echo "$R/v"; done) --out r.html
fresh
accept report "report of a run and its verification" "$K" report "$R/a" "$R/v" --out r.html

# --- batch ------------------------------------------------------------------
batch_case() { # DESC MANIFEST-TEXT
    fresh
    cp "$BUMP" part.stl
    printf '%s\n' "$2" >m.toml
    refuse batch "$1" "$K" batch m.toml
}
batch_case "an item whose args are --help" '[[item]]
part = "part.stl"
out = "o"
args = ["--help"]'
batch_case "an item with a missing part" '[[item]]
part = "nope.stl"
out = "o"'
batch_case "two items on one out" '[[item]]
part = "part.stl"
out = "o"
pitch = 8
[[item]]
part = "part.stl"
out = "o"
pitch = 8'
batch_case "an unknown key" '[[item]]
part = "part.stl"
out = "o"
pich = 8'
batch_case "not TOML" 'this is = = not toml'
batch_case "an empty manifest" ''
batch_case "a pitch of -1" '[[item]]
part = "part.stl"
out = "o"
pitch = -1'
batch_case "an out of --out" '[[item]]
part = "part.stl"
out = "o"
args = ["--out", "elsewhere"]'
batch_case "an unknown flag" '[[item]]
part = "part.stl"
out = "o"
args = ["--bogus"]'
batch_case "angles of nonsense" '[[item]]
part = "part.stl"
out = "o"
angles = "a:b:c"'
fresh
mkfifo part.stl
printf '[[item]]\npart = "part.stl"\nout = "o"\n' >m.toml
refuse batch "a FIFO part" "$K" batch m.toml
fresh
refuse batch "a missing manifest" "$K" batch nope.toml
fresh
refuse batch "/dev/zero as the manifest" "$K" batch /dev/zero
fresh
cp "$BUMP" part.stl
printf '[[item]]\npart = "part.stl"\nout = "o"\npitch = 8\nangles = "0"\nargs = ["--threads", "2"]\n' >m.toml
accept batch "a good item" "$K" batch m.toml
accept batch "the same item again (skipped)" "$K" batch m.toml

# --- inputs -----------------------------------------------------------------
fresh
refuse inputs "a missing part" "$K" analyze nope.stl "${FAST[@]}" --out o
fresh
mkdir d.stl
refuse inputs "a folder as the part" "$K" analyze d.stl "${FAST[@]}" --out o
fresh
refuse inputs "/dev/zero as the part" "$K" analyze /dev/zero "${FAST[@]}" --out o
fresh
: >empty.stl
refuse inputs "an empty part" "$K" analyze empty.stl "${FAST[@]}" --out o
fresh
head -c 300 "$BUMP" >cut.stl
refuse inputs "a truncated binary STL" "$K" analyze cut.stl "${FAST[@]}" --out o
fresh
printf 'solid x\nfacet normal 0 0 0\nouter loop\nvertex 0 0 nan\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n' >nan.stl
refuse inputs "a NaN vertex" "$K" analyze nan.stl "${FAST[@]}" --out o
fresh
printf 'solid x\ngarbage\n' >garbage.stl
refuse inputs "ASCII garbage" "$K" analyze garbage.stl "${FAST[@]}" --out o
fresh
python3 -c "import struct,sys; sys.stdout.buffer.write(b'\0'*80+struct.pack('<I',4000000000))" >huge.stl
refuse inputs "a header of 4e9 triangles" "$K" analyze huge.stl "${FAST[@]}" --out o
fresh
cp "$BUMP" "$(printf 'p\xff.stl')"
refuse inputs "a non-UTF-8 part path" "$K" analyze "$(printf 'p\xff.stl')" "${FAST[@]}" --out o
for flag in "--scale -1000" "--scale 0" "--scale 1e300" "--scale nan" "--pitch 0" "--pitch -1" \
    "--pitch nan" "--pitch 1e-9" "--pitch 600" "--angles=91" "--angles=1:0:1" "--angles=-30:30:0" \
    "--angles=nan" "--triangle-side 0" "--radius -1" "--thickness 1e300" "--deflection 45" \
    "--e0 1" "--window 0" "--threads 0" "--threads 100000" "--max-memory 0" "--max-memory -1" \
    "--max-memory nan" "--grid-size 0,0" "--blind-depth 0" "--side up" "--rate x" "--level x"; do
    fresh
    # shellcheck disable=SC2086
    refuse inputs "analyze $flag" "$K" analyze "$BUMP" --pitch 8 --angles=0 $flag --out o
done
fresh
refuse inputs "--out ''" "$K" analyze "$BUMP" "${FAST[@]}" --out ''
fresh
refuse inputs "--pitches 600,300" "$K" converge "$BUMP" --pitches 600,300 --angles=0 --out o
fresh
accept inputs "--pitches 8,16 (coarse last)" "$K" converge "$BUMP" --pitches 8,16 --angles=0 --threads 2 --starts 4 --out o
fresh
refuse inputs "verify --tolerance -1" "$K" verify "$BUMP" "${ONE[@]}" --tolerance -1 --out o
fresh
refuse inputs "verify --tie-band nan" "$K" verify "$BUMP" "${ONE[@]}" --tie-band nan --out o
fresh
refuse inputs "verify --pitch auto" "$K" verify "$BUMP" --pitch auto --angles=0 --out o
fresh
cp -r "$R/a" a
refuse inputs "analyze its own output's part" "$K" analyze a/summary.json "${FAST[@]}" --out a --force

# --- --frame ----------------------------------------------------------------
frame_case() { # refuse|accept DESC MATRIX
    fresh
    printf '%s\n' "$3" >f.txt
    "$1" frame "$2" "$K" analyze "$BUMP" "${FAST[@]}" --no-check --frame @f.txt --out o
}
frame_case accept "identity" '1 0 0 0
0 1 0 0
0 0 1 0'
frame_case accept "45 degrees to 8 decimals" '0.70710678 -0.70710678 0 0
0.70710678 0.70710678 0 0
0 0 1 0'
frame_case accept "an entry off by 5e-10" '1.0000000005 0 0 0
0 1 0 0
0 0 1 0'
frame_case accept "4x4 with its last row" '1 0 0 0
0 1 0 0
0 0 1 0
0 0 0 1'
frame_case accept "a translation" '1 0 0 5
0 1 0 0
0 0 1 0'
frame_case refuse "a mirror" '-1 0 0 0
0 1 0 0
0 0 1 0'
frame_case refuse "a scaling" '2 0 0 0
0 2 0 0
0 0 2 0'
frame_case refuse "off by 1e-3" '1.001 0 0 0
0 1 0 0
0 0 1 0'
frame_case refuse "rows of 4, 3 and 5" '1 0 0 0
0 1 0
0 0 0 1 0'
frame_case refuse "a NaN" '1 0 0 0
0 nan 0 0
0 0 1 0'
frame_case refuse "words" 'one zero zero 0
0 1 0 0
0 0 1 0'
frame_case refuse "9 numbers" '1 0 0
0 1 0
0 0 1'
frame_case refuse "all zero" '0 0 0 0
0 0 0 0
0 0 0 0'
frame_case refuse "a shear" '1 0.5 0 0
0 1 0 0
0 0 1 0'
frame_case refuse "1e300 translation" '1 0 0 1e300
0 1 0 0
0 0 1 0'
fresh
refuse frame "a missing frame file" "$K" analyze "$BUMP" "${FAST[@]}" --frame @nope --out o
fresh
refuse frame "/dev/zero as the frame" "$K" analyze "$BUMP" "${FAST[@]}" --frame @/dev/zero --out o
fresh
mkfifo f
refuse frame "a FIFO frame" "$K" analyze "$BUMP" "${FAST[@]}" --frame @f --out o
for axes in "x,y" "+q,+y,+z" "-x,-x,+z" "+x,+y,+z,+x"; do
    fresh
    refuse frame "--frame $axes" "$K" analyze "$BUMP" "${FAST[@]}" --frame "$axes" --out o
done

# --- signal timing ------------------------------------------------------------
# A run killed by INT or TERM at any moment ends 130/143, leaves no
# debris and the previous result whole; after a KILL, the next --force run
# succeeds and leaves no debris.
for sig in INT TERM KILL; do
    for delay in 0.01 0.05 0.1 0.2 0.3 0.45 0.6 0.8 1.0 1.5 2.0; do
        for cmd in analyze verify converge; do
            fresh
            case $cmd in
            analyze) cp -r "$R/a" o ;;
            verify) cp -r "$R/v" o ;;
            converge) cp -r "$R/c" o ;;
            esac
            before=$(cd o && find . -type f -exec sha256sum {} + | sort)
            if [[ $cmd == analyze ]]; then
                args=(analyze "$BUMP" --pitch 2 --angles=-30:30:5 --threads 2 --force --out o --report)
            elif [[ $cmd == verify ]]; then
                args=(verify "$BUMP" --pitch 4 --angles=-10,0,10 --threads 2 --starts 30 --force --out o)
            else
                args=(converge "$BUMP" --pitches 8,4 --angles=-10,0,10 --threads 2 --starts 30 --force --out o)
            fi
            "$K" "${args[@]}" >/dev/null 2>"$W/err" &
            pid=$!
            sleep "$delay"
            kill -s "$sig" "$pid" 2>/dev/null
            wait "$pid"
            rc=$?
            why=""
            if [[ $sig == KILL ]]; then
                timeout 300 "$K" "${args[@]}" >/dev/null 2>"$W/err"
                rc2=$?
                [[ $rc2 == 0 || $rc2 == 1 || $rc2 == 3 ]] || why="the run after the KILL: exit $rc2 $(head -c 200 "$W/err")"
            else
                after=$( (cd o 2>/dev/null && find . -type f -exec sha256sum {} + | sort))
                if [[ $rc == 130 || $rc == 143 || $rc == 2 ]]; then
                    # The previous result, or (the signal came after the
                    # commit, as the run said) the new one whole.
                    [[ $before == "$after" ]] || { grep -q "already written whole" "$W/err" && whole o; } ||
                        why="the previous result changed"
                elif [[ $rc != 0 && $rc != 1 && $rc != 3 ]]; then
                    why="exit $rc"
                fi
            fi
            [[ -z $(debris) ]] || why="$why; debris $(debris)"
            record signals "$cmd $sig after ${delay}s" "$([[ -z $why ]] && echo 1 || echo 0)" "$why"
        done
    done
done

# --- full and read-only disks -------------------------------------------------
if mkdir -p "$W/full" "$W/ro" && mount -t tmpfs -o size=16k tmpfs "$W/full" 2>/dev/null &&
    mount -t tmpfs -o ro,size=1m tmpfs "$W/ro" 2>/dev/null; then
    for cmd in "analyze $BUMP ${ONE[*]}" "verify $BUMP ${ONE[*]} --starts 4" \
        "converge $BUMP --pitches 16,8 --angles=0 --threads 2 --starts 3" "merge $R/as1 $R/as2"; do
        cd "$W/ro" || exit 1
        # shellcheck disable=SC2086
        refuse disks "${cmd%% *} --out on a read-only disk" "$K" $cmd --out o
        cd "$W/full" || exit 1
        dd if=/dev/zero of=filler bs=4k 2>/dev/null
        # shellcheck disable=SC2086
        fails disks "${cmd%% *} --out on a full disk" "$K" $cmd --out o
        rm -rf "$W/full"/* "$W/full"/.[!.]* 2>/dev/null
    done
    cd "$W/full" || exit 1
    dd if=/dev/zero of=filler bs=4k 2>/dev/null
    fails disks "report on a full disk" "$K" report "$R/a" "$R/v" --out r.html
    rm -f filler
    # A full disk under an existing result: the result stays whole.
    cd "$W" && umount "$W/full" && mount -t tmpfs -o size=1m tmpfs "$W/full" && cd "$W/full" || exit 1
    cp -r "$R/anocheck" o 2>/dev/null
    dd if=/dev/zero of=filler bs=4k 2>/dev/null
    if [[ -d o ]]; then
        before=$(snap)
        "$K" analyze "$BUMP" --pitch 2 --angles=-30:30:5 --threads 2 --no-check --points-csv --force --out o >/dev/null 2>"$W/err"
        rc=$?
        after=$(snap)
        why=""
        [[ $rc == 2 && $before == "$after" && -z $(debris) ]] || why="exit $rc; changed or debris"
        record disks "analyze --force over a result on a full disk" "$([[ -z $why ]] && echo 1 || echo 0)" "$why"
    fi
    cd "$W" || exit 1
    umount "$W/full" "$W/ro"
fi
fresh
refuse disks "--out under /proc" "$K" analyze "$BUMP" "${FAST[@]}" --out /proc/kneeform-out
fresh
refuse disks "--out under a file" "$K" analyze "$BUMP" "${FAST[@]}" --out "$BUMP/o"

# --- memory limits ------------------------------------------------------------
for m in 0.001 0.01 0.03; do
    fresh
    refuse memory "analyze --max-memory $m" "$K" analyze "$BUMP" --pitch 1 --angles=-30:30:1 --max-memory "$m" --out o
    fresh
    refuse memory "verify --max-memory $m" "$K" verify "$BUMP" --pitch 1 --angles=0 --starts 4 --max-memory "$m" --out o
    fresh
    refuse memory "converge --max-memory $m" "$K" converge "$BUMP" --pitches 2,1 --angles=0 --starts 4 --max-memory "$m" --out o
done
"$K" scenario bump --triangles 400000 --out "$P/big.stl" >/dev/null 2>&1
for kib in 60000 100000 150000 200000 250000 300000 350000 400000 500000 700000 1000000; do
    for cmd in "analyze $P/big.stl ${ONE[*]}" "verify $P/big.stl ${ONE[*]} --starts 4" \
        "converge $P/big.stl --pitches 16,8 --angles=0 --threads 2 --starts 3" \
        "merge $R/as1 $R/as2" "report $R/a $R/v"; do
        fresh
        out=(--out o)
        [[ $cmd == report* ]] && out=(--out r.html)
        sh -c "ulimit -v $kib; exec $K $cmd ${out[*]}" >/dev/null 2>"$W/err"
        rc=$?
        why=""
        if [[ $rc == 2 ]]; then
            lines=$(grep -vc '^kneeform: exact oracle: about' "$W/err")
            [[ $lines == 1 ]] || why="$lines lines"
            [[ ! -e o && ! -e r.html ]] || why="$why; an output"
        elif [[ $rc != 0 && $rc != 1 && $rc != 3 ]]; then
            why="exit $rc"
        fi
        grep -qE 'panicked|memory allocation|backtrace' "$W/err" && why="$why; a panic or an abort"
        [[ -z $(debris) ]] || why="$why; debris $(debris)"
        record memory "${cmd%% *} under ulimit -v $kib" "$([[ -z $why ]] && echo 1 || echo 0)" "$why: $(head -c 200 "$W/err")"
    done
done

# --- concurrent runs -----------------------------------------------------------
for pair in "analyze analyze" "verify verify" "analyze verify" "converge verify" "merge analyze"; do
    for gap in 0 0.05 0.3; do
        fresh
        cmd_of() {
            case $1 in
            analyze) echo "analyze $BUMP --pitch 4 --angles=-30:30:10 --threads 2" ;;
            verify) echo "verify $BUMP --pitch 4 --angles=0 --threads 2 --starts 20" ;;
            converge) echo "converge $BUMP --pitches 8,4 --angles=0 --threads 2 --starts 10" ;;
            merge) echo "merge $R/ap1 $R/ap2" ;;
            esac
        }
        set -- $pair
        # shellcheck disable=SC2046
        "$K" $(cmd_of "$1") --out o >/dev/null 2>"$W/err1" &
        p1=$!
        sleep "$gap"
        # shellcheck disable=SC2046
        "$K" $(cmd_of "$2") --out o >/dev/null 2>"$W/err2" &
        p2=$!
        wait "$p1"
        r1=$?
        wait "$p2"
        r2=$?
        why=""
        ok=0
        for r in $r1 $r2; do [[ $r == 0 || $r == 1 || $r == 3 ]] && ok=$((ok + 1)); done
        # Exactly one writes o; the other is refused in a line (or both
        # ran one after the other, the second refused by the first's o).
        [[ $ok == 1 ]] || why="$ok of two succeeded (exits $r1 $r2)"
        for e in 1 2; do
            r=$([[ $e == 1 ]] && echo $r1 || echo $r2)
            if [[ $r == 2 ]]; then
                [[ $(wc -l <"$W/err$e") == 1 ]] || why="$why; the refused run said $(wc -l <"$W/err$e") lines"
            fi
        done
        [[ -z $(debris) ]] || why="$why; debris $(debris)"
        [[ -f o/kneeform-run.json ]] || why="$why; no whole result"
        record concurrent "$pair ${gap}s apart" "$([[ -z $why ]] && echo 1 || echo 0)" "$why"
    done
done

# --- the table --------------------------------------------------------------------
echo "| class | tried | held |"
echo "|---|---:|---:|"
total=0
held=0
for c in "${CLASSES[@]}"; do
    echo "| $c | ${TRIED[$c]} | ${HELD[$c]} |"
    total=$((total + TRIED[$c]))
    held=$((held + HELD[$c]))
done
echo "| all | $total | $held |"
