#!/usr/bin/env bash
# Studies spread over machines (issue 20): `sweep --shard K/N` in three shards, merged by
# `stepbench merge`, equals the unsharded sweep in every accuracy field, and so does a
# partial merge merged with the shard it lacks (scans too); the merge refuses
# overlapping, missing, foreign and differently configured shards in one line, writing
# nothing; and two timed shards of `stepbench_bench --shard=K/N` merge with each
# problem's machine recorded.
set -u
bin=${1:?usage: shard_test.sh path/to/stepbench path/to/stepbench_bench}
bench=${2:?usage: shard_test.sh path/to/stepbench path/to/stepbench_bench}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0 passes=0
ok() { passes=$((passes + 1)); }
bad() { echo "FAIL: $*"; fails=$((fails + 1)); }

# expect_error "<what the message must contain>" args...: one line on stderr, exit 2.
expect_error() {
  local want=$1; shift
  "$bin" "$@" >"$work/out" 2>"$work/err"
  local rc=$?
  local lines; lines=$(wc -l <"$work/err")
  if [ "$rc" -ne 2 ]; then bad "exit $rc, not 2, for: $* :: $(cat "$work/err")"; return; fi
  if [ "$lines" -ne 1 ]; then bad "$lines lines on stderr for: $* :: $(cat "$work/err")"; return; fi
  grep -qi -- "$want" "$work/err" || { bad "message lacks '$want' for: $* :: $(cat "$work/err")"; return; }
  ok
}

problems=(--problem constant_acceleration --problem projectile --problem damped_spring --problem pendulum)
"$bin" sweep "${problems[@]}" --quick --quiet --out "$work/whole.h5" 2>"$work/err" || bad "the unsharded sweep: $(cat "$work/err")"
for k in 1 2 3; do
  "$bin" sweep "${problems[@]}" --quick --quiet --shard "$k/3" --out "$work/s$k.h5" 2>"$work/err" ||
    bad "sweep --shard $k/3: $(cat "$work/err")"
done
# Given in any order, the shards merge to the study's order.
"$bin" merge "$work/s3.h5" "$work/s1.h5" "$work/s2.h5" -o "$work/merged.h5" 2>"$work/err" &&
  grep -q "4 problems of 4 from 3 shards" "$work/err" && ok || bad "merge: $(cat "$work/err")"

# same_study A B [PATH@ATTR ...]: every dataset and attribute of A and B equal, bit for bit
# (NaN equal to NaN), except what measures the wall clock of one run or the moment of
# writing (and the attributes named):
#   /@created_utc, /@wall_seconds         when the file was written, how long the sweep took
#                                         (a merge: the sum of its shards')
#   /stability@limits_seconds, @regions_seconds, /loop@wall_seconds, /energy@wall_seconds,
#   /problems/*/reference/*@wall_seconds  how long each part or reference solve took
#   /energy/*/summary field `seconds`     the wall time of each energy run
# The shard attributes themselves (a shard says shard K of 3; the merge 0 of 1, as the
# unsharded study) are checked on their own below.
cat >"$work/same_study.py" <<'PY'
import fnmatch, sys
import h5py, numpy as np
EXCLUDED_ATTRS = [("/", "created_utc"), ("/", "wall_seconds"), ("/stability", "limits_seconds"),
                  ("/stability", "regions_seconds"), ("/loop", "wall_seconds"), ("/energy", "wall_seconds"),
                  ("/problems/*/reference/*", "wall_seconds")]
EXCLUDED_FIELDS = [("/energy/*/summary", "seconds")]
whole, merged = h5py.File(sys.argv[1]), h5py.File(sys.argv[2])
EXCLUDED_ATTRS += [tuple(a.split("@")) for a in sys.argv[3:]]
def excluded(rules, path, name):
    return any(fnmatch.fnmatchcase(path, p) and name == n for p, n in rules)
def same(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
def objects(f):
    out = {"/": f}
    def add(name, obj):
        out["/" + name] = obj  # returns None: visititems goes on
    f.visititems(add)
    return out
ow, om = objects(whole), objects(merged)
assert ow.keys() == om.keys(), sorted(ow.keys() ^ om.keys())
datasets = attrs = 0
for path, a in ow.items():
    b = om[path]
    assert set(a.attrs) == set(b.attrs), (path, set(a.attrs) ^ set(b.attrs))
    for name in a.attrs:
        if excluded(EXCLUDED_ATTRS, path, name):
            continue
        assert same(a.attrs[name], b.attrs[name]), (path, name, a.attrs[name], b.attrs[name])
        attrs += 1
    if isinstance(a, h5py.Dataset):
        x, y = a[()], b[()]
        assert x.dtype == y.dtype and x.shape == y.shape, path
        for field in x.dtype.names or [None]:
            if field and excluded(EXCLUDED_FIELDS, path, field):
                continue
            assert same(x[field] if field else x, y[field] if field else y), (path, field)
        datasets += 1
# Not an empty comparison: a study's datasets and attributes, or a scan file's.
assert (datasets > 150 and attrs > 1500) if len(whole.get("problems", {})) else (datasets > 3 and attrs > 20), (datasets, attrs)
PY
same_study() { /usr/bin/python3 "$work/same_study.py" "$@"; }
same_study "$work/whole.h5" "$work/merged.h5" && ok || bad "the merged study differs from the unsharded one"
/usr/bin/python3 - "$work/whole.h5" "$work/merged.h5" "$work/s1.h5" "$work/s2.h5" "$work/s3.h5" <<'PY' && ok || bad "the merged study's order or the shards' shares"
import sys
import h5py
whole, merged = h5py.File(sys.argv[1]), h5py.File(sys.argv[2])
shards = [h5py.File(p) for p in sys.argv[3:]]
assert list(merged["verdict/equal_error"]["problem"][::11]) == [b"constant_acceleration", b"projectile",
                                                                b"damped_spring", b"pendulum"]
# The shards: each holds its share, the same selection, and no problem twice.
held = [sorted(s["problems"]) for s in shards]
assert sorted(sum(held, [])) == sorted(whole["problems"]), held
assert all(h for h in held), held
for k, s in enumerate(shards):
    assert (s.attrs["shard_index"], s.attrs["shard_count"]) == (k, 3)
    assert s.attrs["selection"] == "constant_acceleration,projectile,damped_spring,pendulum"
    assert s.attrs["sweep_options"] == whole.attrs["sweep_options"]
for f in (whole, merged):
    assert (f.attrs["shard_index"], f.attrs["shard_count"]) == (0, 1)
# The study-wide parts travel with their problems: the loop with pendulum and
# damped_spring, the energy study with pendulum; /stability in every shard.
owner = {p: k for k, h in enumerate(held) for p in h}
for k, s in enumerate(shards):
    assert sorted(s.get("loop", {})) == sorted(p for p in ("damped_spring", "pendulum") if owner[p] == k)
    assert sorted(s.get("energy", {})) == (["pendulum"] if owner["pendulum"] == k else [])
    assert "stability" in s
PY

# Refusals: one line, exit 2, no file.
cp "$work/s1.h5" "$work/s1copy.h5"
expect_error "both hold shard 1 of 3 (overlapping shards)" merge "$work/s1.h5" "$work/s1copy.h5" "$work/s2.h5" "$work/s3.h5" -o "$work/x.h5"
/usr/bin/python3 -c '
import h5py, sys
with h5py.File(sys.argv[1], "r+") as f: f.attrs["shard_index"] = 1' "$work/s1copy.h5"
expect_error "is in two shards" merge "$work/s1.h5" "$work/s1copy.h5" "$work/s3.h5" -o "$work/x.h5"
/usr/bin/python3 - "$work" <<'PY'
import h5py, sys
problems = {k: sorted(h5py.File(f"{sys.argv[1]}/s{k}.h5")["problems"]) for k in (1, 2, 3)}
open(f"{sys.argv[1]}/missing.txt", "w").write(", ".join(p for p in ["constant_acceleration", "projectile", "damped_spring", "pendulum"] if p in problems[2]))
PY
missing=$(cat "$work/missing.txt")
expect_error "selected problems* \(is\|are\) in no shard ($missing): shard 2 of 3 not given; --partial" merge "$work/s1.h5" "$work/s3.h5" -o "$work/x.h5"
# The output may not be one of the inputs: the shard is left as it was.
sum_before=$(md5sum <"$work/s1.h5")
expect_error "the output '.*s1.h5' is one of the shards" merge "$work/s1.h5" "$work/s2.h5" "$work/s3.h5" -o "$work/s1.h5"
[ "$(md5sum <"$work/s1.h5")" = "$sum_before" ] && ok || bad "merge -o an input changed it"
cp "$work/s2.h5" "$work/other_build.h5"
/usr/bin/python3 -c '
import h5py, sys
with h5py.File(sys.argv[1], "r+") as f: f.attrs["git_commit"] = "0123456789ab"' "$work/other_build.h5"
expect_error "was written by another build" merge "$work/s1.h5" "$work/other_build.h5" "$work/s3.h5" -o "$work/x.h5"
"$bin" sweep "${problems[@]}" --quick --quiet --shard 2/3 --set damped_spring.k_s=20 --out "$work/s2set.h5" 2>/dev/null
expect_error "differ in their options: .* has overrides: none, .* has overrides: damped_spring.k_s=20" merge "$work/s1.h5" "$work/s2set.h5" "$work/s3.h5" -o "$work/x.h5"
"$bin" sweep "${problems[@]}" --quick --quiet --shard 2/3 --base-steps 64 --out "$work/s2base.h5" 2>/dev/null
expect_error "differ in their options: .* has base_steps: 32, .* has base_steps: 64" merge "$work/s1.h5" "$work/s2base.h5" "$work/s3.h5" -o "$work/x.h5"
"$bin" sweep --problem constant_acceleration --problem projectile --quick --quiet --shard 2/3 --out "$work/s2sel.h5" 2>/dev/null
expect_error "differ in their selection of problems" merge "$work/s1.h5" "$work/s2sel.h5" "$work/s3.h5" -o "$work/x.h5"
"$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e3:3:log --hz 60 --substeps 1 --quiet --out "$work/scan.h5" >/dev/null
expect_error "is a study shard and .* a scan file" merge "$work/s1.h5" "$work/scan.h5" -o "$work/x.h5"
[ ! -e "$work/x.h5" ] && ok || bad "a refused merge wrote its file"
# --partial merges what there is and names what is missing.
"$bin" merge "$work/s1.h5" "$work/s3.h5" --partial -o "$work/partial.h5" 2>"$work/err" &&
  grep -q "in no shard (--partial): $missing" "$work/err" && ok || bad "merge --partial: $(cat "$work/err")"
/usr/bin/python3 - "$work/partial.h5" "$work/s1.h5" "$work/s3.h5" <<'PY' && ok || bad "the partial merge"
import sys, h5py
m = h5py.File(sys.argv[1])
have = sorted(sum((list(h5py.File(p)["problems"]) for p in sys.argv[2:]), []))
assert sorted(m["problems"]) == have, (list(m["problems"]), have)
assert m.attrs["selection"] == "constant_acceleration,projectile,damped_spring,pendulum"
assert {p.decode() for p in m["verdict/equal_error"]["problem"]} == set(have)
# The file names what no shard held.
missing = [p for p in m.attrs["selection"].split(",") if p not in have]
assert missing and m.attrs["missing_problems"] == ",".join(missing), (m.attrs.get("missing_problems"), missing)
PY
# The partial merge names the shards it holds (merged_shards, 0-based, of
# merged_shard_count), so merged with the missing shard, in either order, it is the whole
# study, with nothing left of the partial merge; merged with a shard it holds, or one that
# repeats a problem it holds, it overlaps.
/usr/bin/python3 -c '
import h5py, sys
m = h5py.File(sys.argv[1])
assert list(m.attrs["merged_shards"]) == [0, 2] and m.attrs["merged_shard_count"] == 3, dict(m.attrs)
assert (m.attrs["shard_index"], m.attrs["shard_count"]) == (0, 1)' "$work/partial.h5" && ok ||
  bad "the partial merge does not name its shards"
"$bin" merge "$work/partial.h5" "$work/s2.h5" -o "$work/completed.h5" 2>"$work/err" &&
  grep -q "4 problems of 4 from 3 shards" "$work/err" && ok || bad "completing a partial merge: $(cat "$work/err")"
same_study "$work/whole.h5" "$work/completed.h5" && ok || bad "the completed partial merge differs from the unsharded study"
"$bin" merge "$work/s2.h5" "$work/partial.h5" -o "$work/completed2.h5" 2>"$work/err" &&
  same_study "$work/merged.h5" "$work/completed2.h5" && ok || bad "completing a partial merge, the shard first: $(cat "$work/err")"
expect_error "'.*partial.h5' and '.*s1.h5' both hold shard 1 of 3 (overlapping shards)" merge "$work/partial.h5" "$work/s1.h5" "$work/s2.h5" -o "$work/x.h5"
expect_error "is in two shards, '.*partial.h5' and '.*s1copy.h5' (overlapping shards)" merge "$work/partial.h5" "$work/s1copy.h5" -o "$work/x.h5"
[ ! -e "$work/x.h5" ] && ok || bad "a refused merge wrote its file"

# Scan shards too: a partial merge of shards 1 and 3, merged with shard 2, is the merge
# of the three (but for its wall_seconds, summed in another order).
scan=(scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e3:7:log --hz 60 --substeps 1,2 --quiet)
for k in 1 2 3; do
  "$bin" "${scan[@]}" --shard "$k/3" --out "$work/scan$k.h5" >/dev/null 2>"$work/err" || bad "scan --shard $k/3: $(cat "$work/err")"
done
"$bin" merge "$work"/scan[123].h5 -o "$work/scan_all.h5" 2>/dev/null &&
  "$bin" merge "$work/scan1.h5" "$work/scan3.h5" --partial -o "$work/scan_partial.h5" 2>/dev/null &&
  "$bin" merge "$work/scan_partial.h5" "$work/scan2.h5" -o "$work/scan_completed.h5" 2>"$work/err" &&
  same_study "$work/scan_all.h5" "$work/scan_completed.h5" /scan/stiff_spring@wall_seconds && ok ||
  bad "completing a partial scan merge: $(cat "$work/err")"
expect_error "grid point .* is in two shards (overlapping shards)" merge "$work/scan_partial.h5" "$work/scan1.h5" -o "$work/x.h5"

"$bin" sweep --problem projectile --quick --quiet --shard 2/2 --out "$work/empty.h5" 2>"$work/err" &&
  grep -q "0 problems: shard 2 of 2" "$work/err" && ok || bad "a shard with no problem: $(cat "$work/err")"

# Timed shards: two stepbench_bench shards merge with each problem's machine; shards
# from two machines (the second's CPU renamed here, as another machine writes it) merge
# with a line on stderr, and the root names both.
for k in 1 2; do
  "$bench" --quick --problem=constant_acceleration --problem=projectile --shard="$k/2" --benchmark_min_time=0.0001 \
    --study_out="$work/t$k.h5" >/dev/null 2>"$work/err" || bad "stepbench_bench --shard=$k/2: $(cat "$work/err")"
done
"$bin" merge "$work/t1.h5" "$work/t2.h5" -o "$work/timed.h5" 2>"$work/err" || bad "merging timed shards: $(cat "$work/err")"
grep -q "machines" "$work/err" && bad "one machine reported as several: $(cat "$work/err")" || ok
cp "$work/t2.h5" "$work/t2other.h5"
/usr/bin/python3 - "$work" <<'PY'
import h5py, sys
w = sys.argv[1]
with h5py.File(f"{w}/t2other.h5", "r+") as f:
    f.attrs["cpu"] = "Test CPU"
    for p in f["problems"].values():
        p.attrs["cpu"] = "Test CPU"
PY
"$bin" merge "$work/t1.h5" "$work/t2other.h5" -o "$work/timed2.h5" 2>"$work/err" &&
  grep -q "the shards ran on 2 machines" "$work/err" && ok || bad "merging shards of two machines: $(cat "$work/err")"
/usr/bin/python3 - "$work" <<'PY' && ok || bad "the timed merge"
import h5py, numpy as np, sys
w = sys.argv[1]
for name, second in (("timed", "t2"), ("timed2", "t2other")):
    t = [h5py.File(f"{w}/{k}.h5") for k in ("t1", second)]
    owner = {p: k for k in (0, 1) for p in t[k]["problems"]}
    assert sorted(owner) == ["constant_acceleration", "projectile"], owner
    m = h5py.File(f"{w}/{name}.h5")
    assert m.attrs["timing"] == 1 and sorted(m["problems"]) == sorted(owner)
    for p, k in owner.items():
        g, src = m["problems"][p], t[k]["problems"][p]
        for a in ("cpu", "cores", "num_cpus", "mhz_per_cpu", "cpu_scaling_enabled"):
            assert g.attrs[a] == src.attrs[a], (name, p, a)
        runs = g["methods/velocity_verlet/runs"][()]
        assert np.array_equal(runs["time_ns"], src["methods/velocity_verlet/runs"][()]["time_ns"], equal_nan=True)
        assert np.isfinite(runs["time_ns"]).any()
    cpus = list(dict.fromkeys(m["problems"][p].attrs["cpu"] for p in ("constant_acceleration", "projectile")))
    assert len(cpus) == (1 if name == "timed" else 2) and m.attrs["cpu"] == "; ".join(cpus), m.attrs["cpu"]
    assert m.attrs["benchmark_wall_seconds"] == t[0].attrs["benchmark_wall_seconds"] + t[1].attrs["benchmark_wall_seconds"]
PY

echo "shard_test: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
