"""The schedulers sharded scans and studies run on (issue 20): the GitHub Actions
workflows are valid YAML with a matrix of shards and a merge job after them; the SLURM
array scripts parse and pass each task its shard; the timed study's shards upload their
Google Benchmark JSON and the merge joins it; a merged study names its machines and what
a partial merge lacks."""
import pathlib
import subprocess

import h5py
import yaml

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_workflow_shards_then_merges():
    doc = yaml.safe_load((ROOT / ".github/workflows/scan-shards.yml").read_text())
    jobs = doc["jobs"]
    shards = jobs["shard"]["strategy"]["matrix"]["shard"]
    assert shards == list(range(1, len(shards) + 1)) and len(shards) >= 2
    runs = " ".join(step.get("run", "") for step in jobs["shard"]["steps"])
    assert f"--shard ${{{{ matrix.shard }}}}/{len(shards)}" in runs
    assert jobs["merge"]["needs"] == "shard"
    merge = " ".join(step.get("run", "") for step in jobs["merge"]["steps"])
    assert "stepbench merge" in merge and "advise --scan" in merge


def test_slurm_script_parses_and_shards():
    script = ROOT / "scripts/slurm/scan-array.sh"
    subprocess.run(["bash", "-n", str(script)], check=True)
    text = script.read_text()
    assert '--shard "${SLURM_ARRAY_TASK_ID}/${SLURM_ARRAY_TASK_COUNT}"' in text
    assert "#SBATCH" in text and "stepbench merge" in text


def _study(cpus, timed=True):
    """A stand-in for a merged study: its root attributes and each problem's machine."""
    from types import SimpleNamespace
    problems = [SimpleNamespace(name=p, attrs={"cpu": c, "cores": "2"}) for p, c in cpus.items()]
    root = {"cpu": "; ".join(dict.fromkeys(cpus.values())), "cores": "2", "benchmark_mode": "quick",
            "created_utc": "2026-12-02T00:00:00Z", "git_commit": "abc"}
    return SimpleNamespace(attrs=root, problems=problems, timed=timed, path="merged.h5")


def test_report_names_each_problems_machine_when_shards_ran_on_several():
    import sys
    sys.path.insert(0, str(ROOT / "scripts"))
    from stepbench_report import report
    one = _study({"pendulum": "AMD EPYC", "kepler": "AMD EPYC"})
    assert report.machines(one) == {}
    assert ", AMD EPYC, " in report.headline(one)
    two = _study({"pendulum": "AMD EPYC", "kepler": "Intel Xeon"})
    assert report.machines(two) == {"pendulum": "AMD EPYC (2 cores)", "kepler": "Intel Xeon (2 cores)"}
    assert "2 machines (AMD EPYC; Intel Xeon; each problem's in its section" in report.headline(two)


def test_study_workflow_shards_the_timed_study_then_merges():
    doc = yaml.safe_load((ROOT / ".github/workflows/study-shards.yml").read_text())
    jobs = doc["jobs"]
    shards = jobs["shard"]["strategy"]["matrix"]["shard"]
    assert shards == list(range(1, len(shards) + 1)) and len(shards) >= 2
    runs = " ".join(step.get("run", "") for step in jobs["shard"]["steps"])
    assert f"stepbench_bench ${{{{ inputs.bench }}}} --shard=${{{{ matrix.shard }}}}/{len(shards)}" in runs
    assert jobs["merge"]["needs"] == "shard"
    merge = " ".join(step.get("run", "") for step in jobs["merge"]["steps"])
    assert "stepbench merge shards/study-*.h5 -o study.h5" in merge and "scripts/report study.h5" in merge


def test_study_workflow_uploads_and_merges_the_benchmark_json():
    """Each shard writes Google Benchmark's JSON and uploads it beside its study; the merge
    job joins the JSON with the studies (`merge --bench ... --bench-out`), its two globs
    listing the downloaded shards in the same order, and uploads the joined file."""
    jobs = yaml.safe_load((ROOT / ".github/workflows/study-shards.yml").read_text())["jobs"]
    shards = jobs["shard"]["strategy"]["matrix"]["shard"]
    steps = jobs["shard"]["steps"]
    runs = " ".join(step.get("run", "") for step in steps)
    assert "--benchmark_out=bench-${{ matrix.shard }}.json --benchmark_out_format=json" in runs
    uploads = [step for step in steps if step.get("uses", "").startswith("actions/upload-artifact")]
    assert len(uploads) == 1
    assert uploads[0]["with"]["path"].splitlines() == ["study-${{ matrix.shard }}.h5", "bench-${{ matrix.shard }}.json"]
    steps = jobs["merge"]["steps"]
    download = next(step for step in steps if step.get("uses", "").startswith("actions/download-artifact"))
    folder = download["with"]["path"]
    assert download["with"]["merge-multiple"] is True
    merge = " ".join(step.get("run", "") for step in steps)
    assert (f"stepbench merge {folder}/study-*.h5 -o study.h5 --bench {folder}/bench-*.json "
            "--bench-out bench.json") in merge
    # The shell sorts each glob's names: shard k's study and JSON at the same place.
    studies = sorted(f"{folder}/study-{k}.h5" for k in shards)
    benches = sorted(f"{folder}/bench-{k}.json" for k in shards)
    assert [p.split("-")[-1].split(".")[0] for p in studies] == [p.split("-")[-1].split(".")[0] for p in benches]
    final = [step for step in steps if step.get("uses", "").startswith("actions/upload-artifact")]
    assert "bench.json" in final[-1]["with"]["path"].splitlines()


def test_slurm_study_script_parses_and_shards():
    script = ROOT / "scripts/slurm/study-array.sh"
    subprocess.run(["bash", "-n", str(script)], check=True)
    text = script.read_text()
    assert '--shard="${SLURM_ARRAY_TASK_ID}/${SLURM_ARRAY_TASK_COUNT}"' in text
    # One folder a shard: each writes its bench.json beside its study.
    assert '--study_out="$out/study.h5"' in text and 'out="results/shards/study-${SLURM_ARRAY_TASK_ID}"' in text
    assert "#SBATCH" in text and "stepbench merge results/shards/study-*/study.h5" in text
    # The merge joins the bench.json beside each study, by the same glob's folders.
    assert "--bench results/shards/study-*/bench.json --bench-out results/bench.json" in text


def test_a_partial_merge_says_what_it_lacks(stepbench, tmp_path):
    """A study merged with --partial names the problems no shard held (missing_problems),
    and the report's headline says so; a whole merge, or the partial one merged with the
    shard it lacks, says nothing of the kind."""
    import sys
    sys.path.insert(0, str(ROOT / "scripts"))
    from stepbench_report import report, study as study_mod
    problems = ["--problem", "constant_acceleration", "--problem", "projectile", "--problem", "falling_drag"]
    for k in (1, 2, 3):
        subprocess.run([stepbench, "sweep", *problems, "--quick", "--quiet", "--shard", f"{k}/3",
                        "--out", str(tmp_path / f"s{k}.h5")], check=True, capture_output=True)
    held = {k: list(h5py.File(tmp_path / f"s{k}.h5")["problems"]) for k in (1, 2, 3)}
    subprocess.run([stepbench, "merge", str(tmp_path / "s1.h5"), str(tmp_path / "s3.h5"), "--partial",
                    "-o", str(tmp_path / "partial.h5")], check=True, capture_output=True)
    s = study_mod.load(str(tmp_path / "partial.h5"))
    assert s.attrs["missing_problems"] == held[2] and held[2]
    assert f"({', '.join(held[2])})" in report.headline(s) and "A partial merge" in report.headline(s)
    subprocess.run([stepbench, "merge", *(str(tmp_path / f"s{k}.h5") for k in (1, 2, 3)),
                    "-o", str(tmp_path / "whole.h5")], check=True, capture_output=True)
    whole = study_mod.load(str(tmp_path / "whole.h5"))
    assert "missing_problems" not in h5py.File(tmp_path / "whole.h5").attrs
    assert whole.attrs["missing_problems"] == [] and "partial" not in report.headline(whole)
    # The partial merge names its shards; merged with the one it lacks, it is whole.
    assert list(h5py.File(tmp_path / "partial.h5").attrs["merged_shards"]) == [0, 2]
    subprocess.run([stepbench, "merge", str(tmp_path / "partial.h5"), str(tmp_path / "s2.h5"),
                    "-o", str(tmp_path / "completed.h5")], check=True, capture_output=True)
    attrs = h5py.File(tmp_path / "completed.h5").attrs
    assert not {"missing_problems", "merged_shards", "merged_shard_count"} & set(attrs)
    completed = study_mod.load(str(tmp_path / "completed.h5"))
    assert completed.attrs["missing_problems"] == [] and "partial" not in report.headline(completed)
