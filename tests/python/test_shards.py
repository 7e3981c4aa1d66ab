"""The schedulers a sharded scan runs on (issue 20): the GitHub Actions workflow is valid
YAML with a matrix of shards and a merge job after them; the SLURM array script parses
and passes each task its shard."""
import pathlib
import subprocess

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
