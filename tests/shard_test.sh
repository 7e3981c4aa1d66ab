#!/usr/bin/env bash
# Studies spread over machines (issue 20): `sweep --shard K/N` in three shards, merged by
# `stepbench merge`, equals the unsharded sweep in every accuracy field, and so does a
# partial merge merged with the shard it lacks (scans too); the merge refuses
# overlapping, missing, foreign and differently configured shards in one line, writing
# nothing; the shards' Google Benchmark JSON joins with them (`--bench`); and two timed
# shards of `stepbench_bench --shard=K/N` merge with each problem's machine recorded,
# their JSON with each shard's context.
set -u
bin=${1:?usage: shard_test.sh path/to/stepbench path/to/stepbench_bench}
bench=${2:?usage: shard_test.sh path/to/stepbench path/to/stepbench_bench}
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"


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
expect_error_re "both hold shard 1 of 3 (overlapping shards)" merge "$work/s1.h5" "$work/s1copy.h5" "$work/s2.h5" "$work/s3.h5" -o "$work/x.h5"
/usr/bin/python3 -c '
import h5py, sys
with h5py.File(sys.argv[1], "r+") as f: f.attrs["shard_index"] = 1' "$work/s1copy.h5"
expect_error_re "is in two shards" merge "$work/s1.h5" "$work/s1copy.h5" "$work/s3.h5" -o "$work/x.h5"
/usr/bin/python3 - "$work" <<'PY'
import h5py, sys
problems = {k: sorted(h5py.File(f"{sys.argv[1]}/s{k}.h5")["problems"]) for k in (1, 2, 3)}
open(f"{sys.argv[1]}/missing.txt", "w").write(", ".join(p for p in ["constant_acceleration", "projectile", "damped_spring", "pendulum"] if p in problems[2]))
PY
missing=$(cat "$work/missing.txt")
expect_error_re "selected problems* \(is\|are\) in no shard ($missing): shard 2 of 3 not given; --partial" merge "$work/s1.h5" "$work/s3.h5" -o "$work/x.h5"
# The output may not be one of the inputs: the shard is left as it was.
sum_before=$(md5sum <"$work/s1.h5")
expect_error_re "the output '.*s1.h5' is one of the shards" merge "$work/s1.h5" "$work/s2.h5" "$work/s3.h5" -o "$work/s1.h5"
[ "$(md5sum <"$work/s1.h5")" = "$sum_before" ] && ok || bad "merge -o an input changed it"
cp "$work/s2.h5" "$work/other_build.h5"
/usr/bin/python3 -c '
import h5py, sys
with h5py.File(sys.argv[1], "r+") as f: f.attrs["git_commit"] = "0123456789ab"' "$work/other_build.h5"
expect_error_re "was written by another build" merge "$work/s1.h5" "$work/other_build.h5" "$work/s3.h5" -o "$work/x.h5"
# Merge reads the options and the selection from these two attributes: a shard with
# another --set, --base-steps or --problem selection, written over a copy (a sweep each
# took 8 to 13 s of the sanitizer stage).
cp "$work/s2.h5" "$work/s2set.h5"
cp "$work/s2.h5" "$work/s2base.h5"
cp "$work/s2.h5" "$work/s2sel.h5"
/usr/bin/python3 - "$work/s2set.h5" "$work/s2base.h5" "$work/s2sel.h5" <<'PY' || bad "h5py edit of the shards"
import sys, h5py
for path, old, new in ((sys.argv[1], "\noverrides: none\n", "\noverrides: damped_spring.k_s=20\n"),
                       (sys.argv[2], "\nbase_steps: 32\n", "\nbase_steps: 64\n")):
    with h5py.File(path, "r+") as f:
        text = f.attrs["sweep_options"]
        assert old in text, text
        f.attrs["sweep_options"] = text.replace(old, new)
with h5py.File(sys.argv[3], "r+") as f:
    f.attrs["selection"] = "constant_acceleration,projectile"
PY
expect_error_re "differ in their options: .* has overrides: none, .* has overrides: damped_spring.k_s=20" merge "$work/s1.h5" "$work/s2set.h5" "$work/s3.h5" -o "$work/x.h5"
expect_error_re "differ in their options: .* has base_steps: 32, .* has base_steps: 64" merge "$work/s1.h5" "$work/s2base.h5" "$work/s3.h5" -o "$work/x.h5"
expect_error_re "differ in their selection of problems" merge "$work/s1.h5" "$work/s2sel.h5" "$work/s3.h5" -o "$work/x.h5"
"$bin" scan --problem stiff_spring --param stiff_spring.k_s=1e1:1e3:3:log --hz 60 --substeps 1 --quiet --out "$work/scan.h5" >/dev/null
expect_error_re "is a study shard and .* a scan file" merge "$work/s1.h5" "$work/scan.h5" -o "$work/x.h5"
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
expect_error_re "'.*partial.h5' and '.*s1.h5' both hold shard 1 of 3 (overlapping shards)" merge "$work/partial.h5" "$work/s1.h5" "$work/s2.h5" -o "$work/x.h5"
expect_error_re "is in two shards, '.*partial.h5' and '.*s1copy.h5' (overlapping shards)" merge "$work/partial.h5" "$work/s1copy.h5" -o "$work/x.h5"
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
expect_error_re "grid point .* is in two shards (overlapping shards)" merge "$work/scan_partial.h5" "$work/scan1.h5" -o "$work/x.h5"

# Each shard's Google Benchmark JSON, crafted here for the sweep's shards as stepbench_bench
# writes it (its context names its shard; a counter may be NaN, written bare), joins with
# the study (`merge --bench ... --bench-out`): the shards' benchmarks in shard order
# whatever order the files are given in, each naming its shard, their family_index
# renumbered so no two shards share one; the context the first shard's, and every
# shard's own (its machine) in stepbench_shards; the machine's own benchmark (the STREAM
# triad) kept from every shard. compare.py reads the file.
/usr/bin/python3 - "$work" <<'PY'
import json, sys, h5py
w = sys.argv[1]
for k in (1, 2, 3):
    problems = list(h5py.File(f"{w}/s{k}.h5")["problems"])
    rows = []
    for family, name in enumerate([f"{p}/rk4" for p in problems] + ["stream/triad"]):
        for i, arg in enumerate(("dt:0.1", "dt:0.05")):
            run = f"{name}/{arg}/real_time"
            rows.append({"name": run, "family_index": family, "per_family_instance_index": i, "run_name": run,
                         "run_type": "iteration", "repetitions": 1, "repetition_index": 0, "threads": 1,
                         "iterations": 100 * k, "real_time": 1.5 * k + i, "cpu_time": 1.5 * k + i, "time_unit": "us",
                         "err_pos_final": float("nan") if i else 1e-3})
    context = {"date": f"2026-12-0{k}T10:00:00+00:00", "host_name": f"node{k}", "executable": "build/stepbench_bench",
               "num_cpus": 2 * k, "mhz_per_cpu": 1000 * k, "cpu_scaling_enabled": False,
               "caches": [{"type": "Data", "level": 1, "size": 32768 * k, "num_sharing": 1}],
               "load_avg": [0.5 * k], "library_build_type": "release", "stepbench_shard": f"{k}/3"}
    with open(f"{w}/c{k}.json", "w") as f:
        json.dump({"context": context, "benchmarks": rows}, f, indent=2)
PY
"$bin" merge "$work/s3.h5" "$work/s1.h5" "$work/s2.h5" -o "$work/mb.h5" --bench "$work/c3.json" "$work/c1.json" \
  "$work/c2.json" --bench-out "$work/cb.json" 2>"$work/err" &&
  grep -q "merge: 14 benchmarks of 3 shards into .*cb.json" "$work/err" && ok || bad "merge --bench: $(cat "$work/err")"
/usr/bin/python3 - "$work" <<'PY' && ok || bad "the joined benchmark JSON"
import json, sys
w = sys.argv[1]
shards = [json.load(open(f"{w}/c{k}.json")) for k in (1, 2, 3)]
text = open(f"{w}/cb.json").read()
joined = json.loads(text)
assert "NaN" in text and "\\u0001" not in text
rows = joined["benchmarks"]
assert [b["name"] for b in rows] == [b["name"] for s in shards for b in s["benchmarks"]]
assert [b["stepbench_shard"] for b in rows] == [s["context"]["stepbench_shard"] for s in shards for b in s["benchmarks"]]
# Each shard's families after the previous shard's: one index a family, increasing.
families = [(b["stepbench_shard"], b["name"].rsplit("/", 2)[0]) for b in rows]
index = {f: b["family_index"] for f, b in zip(families, rows)}
assert len(set(index.values())) == len(index) and [b["family_index"] for b in rows] == sorted(b["family_index"] for b in rows)
for b, s in zip(rows, (b for s in shards for b in s["benchmarks"])):
    assert {k: v for k, v in b.items() if k not in ("family_index", "stepbench_shard")} == \
        {k: v for k, v in s.items() if k not in ("family_index",)} or b["err_pos_final"] != b["err_pos_final"]
assert sum(b["name"].startswith("stream/triad/") for b in rows) == 6
context = dict(shards[0]["context"])
del context["stepbench_shard"]
context["stepbench_shards"] = [s["context"] for s in shards]
assert joined["context"] == context, joined["context"]
PY
compare=/usr/share/benchmark/compare.py
if [ -e "$compare" ]; then
  /usr/bin/python3 "$compare" benchmarks "$work/c2.json" "$work/cb.json" >"$work/out" 2>&1 &&
    [ "$(grep -c "/rk4/dt:" "$work/out")" -eq "$(grep -c '"name": "[a-z_]*/rk4/dt:' "$work/c2.json")" ] && ok ||
    bad "compare.py on the joined JSON: $(cat "$work/out")"
fi
# A partial merge's JSON names the shards it holds: merged with the missing shard's, it is
# the JSON of the three, byte for byte.
"$bin" merge "$work/s1.h5" "$work/s3.h5" --partial -o "$work/pb.h5" --bench "$work/c1.json" "$work/c3.json" \
  --bench-out "$work/pb.json" 2>/dev/null &&
  "$bin" merge "$work/pb.h5" "$work/s2.h5" -o "$work/pbc.h5" --bench "$work/pb.json" "$work/c2.json" \
    --bench-out "$work/pbc.json" 2>"$work/err" && cmp -s "$work/pbc.json" "$work/cb.json" && ok ||
  bad "completing a partial merge's benchmark JSON: $(cat "$work/err") $(diff "$work/pbc.json" "$work/cb.json" | head -5)"
# Refusals, one line and nothing written: the previous outputs are left as they were.
printf 'previous\n' >"$work/xb.json"
/usr/bin/python3 - "$work" <<'PY'
import json, sys
w = sys.argv[1]
dup = json.load(open(f"{w}/c2.json"))
dup["benchmarks"].append(dict(json.load(open(f"{w}/c1.json"))["benchmarks"][0]))
json.dump(dup, open(f"{w}/c2dup.json", "w"))
PY
printf '{"context": {}, "benchmarks": [' >"$work/cbad.json"
b=(-o "$work/x.h5" --bench-out "$work/xb.json")
s123=("$work/s1.h5" "$work/s2.h5" "$work/s3.h5")
expect_error_re "2 benchmark JSON files (--bench) for 3 study files" merge "${s123[@]}" --bench "$work/c1.json" "$work/c2.json" "${b[@]}"
expect_error_re "'.*c2.json' is the benchmark JSON of shard 2 of 3, and its study file '.*s1.h5' holds shard 1 of 3; give --bench in the order" \
  merge "${s123[@]}" --bench "$work/c2.json" "$work/c1.json" "$work/c3.json" "${b[@]}"
expect_error_re "is the benchmark JSON of shard 2 of 3, and its study file '.*pb.h5' holds shards 1, 3 of 3" \
  merge "$work/pb.h5" "$work/s2.h5" --bench "$work/c2.json" "$work/pb.json" "${b[@]}"
expect_error_re "benchmark '[a-z_]*/rk4/dt:0.1/real_time' is in shard 1 of 3 ('.*c1.json') and shard 2 of 3 ('.*c2dup.json') (overlapping shards)" \
  merge "${s123[@]}" --bench "$work/c1.json" "$work/c2dup.json" "$work/c3.json" "${b[@]}"
expect_error_re "'.*c1.json' is named twice (overlapping shards)" merge "${s123[@]}" --bench "$work/c1.json" "$work/c1.json" "$work/c3.json" "${b[@]}"
expect_error_re "the output '.*c1.json' is one of the shards" merge "${s123[@]}" --bench "$work/c1.json" "$work/c2.json" "$work/c3.json" -o "$work/x.h5" --bench-out "$work/c1.json"
expect_error_re "requires --bench-out\|--bench-out is required\|needs --bench-out" merge "${s123[@]}" --bench "$work/c1.json" "$work/c2.json" "$work/c3.json" -o "$work/x.h5"
expect_error_re "--bench joins the benchmark JSON of timed study shards; these are scan files" \
  merge "$work"/scan[123].h5 --bench "$work/c1.json" "$work/c2.json" "$work/c3.json" "${b[@]}"
expect_file_error "cannot read '.*cbad.json': not JSON" merge "${s123[@]}" --bench "$work/c1.json" "$work/cbad.json" "$work/c3.json" "${b[@]}"
[ ! -e "$work/x.h5" ] && [ "$(cat "$work/xb.json")" = previous ] && ! ls "$work"/*.tmp.* >/dev/null 2>&1 && ok ||
  bad "a refused merge wrote a file: $(ls "$work")"

"$bin" sweep --problem projectile --quick --quiet --shard 2/2 --out "$work/empty.h5" 2>"$work/err" &&
  grep -q "0 problems: shard 2 of 2" "$work/err" && ok || bad "a shard with no problem: $(cat "$work/err")"
# Such a shard times nothing, and Google Benchmark writes it an empty JSON file: joined as
# a shard without benchmarks or context; an empty file for a shard with problems is not.
"$bin" sweep --problem projectile --quick --quiet --shard 1/2 --out "$work/one.h5" 2>/dev/null
printf '{"context": {"host_name": "node1", "stepbench_shard": "1/2"}, "benchmarks": [{"name": "projectile/rk4/dt:0.1/real_time", "family_index": 0}]}\n' >"$work/one.json"
: >"$work/empty.json"
"$bin" merge "$work/one.h5" "$work/empty.h5" -o "$work/one_empty.h5" --bench "$work/one.json" "$work/empty.json" \
  --bench-out "$work/one_empty.json" 2>"$work/err" && /usr/bin/python3 -c '
import json, sys
j = json.load(open(sys.argv[1]))
assert j["context"] == {"host_name": "node1", "stepbench_shards": [{"host_name": "node1", "stepbench_shard": "1/2"},
                                                                  {"stepbench_shard": "2/2"}]}, j["context"]
assert [b["stepbench_shard"] for b in j["benchmarks"]] == ["1/2"]' "$work/one_empty.json" && ok ||
  bad "merge --bench with a shard that timed nothing: $(cat "$work/err")"
expect_file_error "cannot read '.*empty.json': it is empty, and its study file '.*one.h5' holds 1 problem" \
  merge "$work/one.h5" "$work/empty.h5" -o "$work/x.h5" --bench "$work/empty.json" "$work/one.json" --bench-out "$work/xb.json"

# Timed shards: two stepbench_bench shards merge with each problem's machine, and their
# benchmark JSON (--benchmark_out) with each shard's context; shards from two machines
# (the second's CPU and host renamed here, as another machine writes them) merge with a
# line on stderr, the root names both, and the JSON keeps both contexts.
for k in 1 2; do
  "$bench" --quick --problem=constant_acceleration --problem=projectile --shard="$k/2" --benchmark_min_time=0.0001 \
    --study_out="$work/t$k.h5" --benchmark_out="$work/tb$k.json" --benchmark_out_format=json >/dev/null 2>"$work/err" ||
    bad "stepbench_bench --shard=$k/2: $(cat "$work/err")"
done
"$bin" merge "$work/t1.h5" "$work/t2.h5" -o "$work/timed.h5" --bench "$work/tb1.json" "$work/tb2.json" \
  --bench-out "$work/timed.json" 2>"$work/err" || bad "merging timed shards: $(cat "$work/err")"
grep -q "machines" "$work/err" && bad "one machine reported as several: $(cat "$work/err")" || ok
cp "$work/t2.h5" "$work/t2other.h5"
/usr/bin/python3 - "$work" <<'PY'
import h5py, json, sys
w = sys.argv[1]
with h5py.File(f"{w}/t2other.h5", "r+") as f:
    f.attrs["cpu"] = "Test CPU"
    for p in f["problems"].values():
        p.attrs["cpu"] = "Test CPU"
other = json.load(open(f"{w}/tb2.json"))
other["context"]["host_name"] = "other-host"
json.dump(other, open(f"{w}/tb2other.json", "w"), indent=2)
PY
"$bin" merge "$work/t2other.h5" "$work/t1.h5" -o "$work/timed2.h5" --bench "$work/tb2other.json" "$work/tb1.json" \
  --bench-out "$work/timed2.json" 2>"$work/err" &&
  grep -q "the shards ran on 2 machines" "$work/err" && ok || bad "merging shards of two machines: $(cat "$work/err")"
/usr/bin/python3 - "$work" <<'PY' && ok || bad "the timed shards' benchmark JSON"
import json, sys
w = sys.argv[1]
shards = [json.load(open(f"{w}/tb{k}.json")) for k in (1, 2)]
assert [s["context"]["stepbench_shard"] for s in shards] == ["1/2", "2/2"]
for name, host in (("timed", shards[1]["context"]["host_name"]), ("timed2", "other-host")):
    joined = json.load(open(f"{w}/{name}.json"))
    rows = joined["benchmarks"]
    assert [b["name"] for b in rows] == [b["name"] for s in shards for b in s["benchmarks"]] and rows
    assert [b["stepbench_shard"] for b in rows] == [f"{k}/2" for k in (1, 2) for b in shards[k - 1]["benchmarks"]]
    machines = {c["stepbench_shard"]: c["host_name"] for c in joined["context"]["stepbench_shards"]}
    assert machines == {"1/2": shards[0]["context"]["host_name"], "2/2": host}, machines
    assert joined["context"]["host_name"] == shards[0]["context"]["host_name"]
    assert "stepbench_shard" not in joined["context"]
PY
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

finish shard_test
