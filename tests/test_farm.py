"""A farm's run: ``--shard auto`` from the farm's environment, ``--resume`` journals that survive a kill, JSON
progress, and a result cache per shard. The truth each is held to is the one unsharded, unbroken run."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.quads import SQUARE, UNIT_UV, quad_obj, trapezoid

from affinity.shards.selection import AutoShard, Shard, parse_shard, shard_from_environment

CLI = [sys.executable, "-m", "affinity.cli"]


def affinity(folder: Path, *args: str, env: dict | None = None) -> subprocess.CompletedProcess:
    """``affinity ARGS`` as a farm runs it: a process in ``folder`` with the farm's variables set."""
    clean = {k: v for k, v in os.environ.items()
             if k not in ("JOB_COMPLETION_INDEX", "AFFINITY_SHARD_COUNT", "CI_NODE_INDEX", "CI_NODE_TOTAL")}
    return subprocess.run([*CLI, *args], capture_output=True, text=True, cwd=folder, timeout=300,
                          env={**clean, **(env or {})})


@pytest.fixture(scope="module")
def library(tmp_path_factory) -> Path:
    """40 meshes with findings (some many), a clean one and an unreadable one."""
    folder = tmp_path_factory.mktemp("library")
    for i in range(40):
        quads = [(trapezoid(0.2 + 0.02 * k, 3 * k), UNIT_UV) for k in range(1 + 7 * (i % 5))]
        (folder / f"prop_{i:02d}.obj").write_text(quad_obj(quads + [(SQUARE, UNIT_UV)] * (50 * (i % 3))))
    (folder / "clean.obj").write_text(quad_obj([(SQUARE, UNIT_UV)]))
    (folder / "broken.obj").write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    return folder


@pytest.fixture(scope="module")
def whole(library) -> subprocess.CompletedProcess:
    """The unsharded, unbroken run: what every farm run below must give."""
    result = affinity(library, "check", "--no-cache", "--format", "json", ".")
    assert result.returncode == 2 and json.loads(result.stdout)["summary"]["files"] == 42
    return result


# --shard auto ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("spec", "env", "expected"), [
    ("auto/4", {"JOB_COMPLETION_INDEX": "0"}, Shard(1, 4)),  # Kubernetes counts from 0
    ("auto/4", {"JOB_COMPLETION_INDEX": "3"}, Shard(4, 4)),
    ("auto", {"JOB_COMPLETION_INDEX": "2", "AFFINITY_SHARD_COUNT": "3"}, Shard(3, 3)),
    ("auto/5", {"JOB_COMPLETION_INDEX": "1", "AFFINITY_SHARD_COUNT": "9"}, Shard(2, 5)),  # the flag wins
    ("auto", {"CI_NODE_INDEX": "1", "CI_NODE_TOTAL": "2"}, Shard(1, 2)),  # GitLab counts from 1
    ("auto/2", {"CI_NODE_INDEX": "2", "CI_NODE_TOTAL": "2"}, Shard(2, 2)),
])
def test_auto_shard_reads_the_farms_variables(spec, env, expected):
    assert shard_from_environment(parse_shard(spec), env) == expected


@pytest.mark.parametrize(("spec", "env", "says"), [
    ("auto", {}, "no shard index in the environment"),
    ("auto", {"JOB_COMPLETION_INDEX": "0"}, "AFFINITY_SHARD_COUNT"),
    ("auto/4", {"JOB_COMPLETION_INDEX": "4"}, "not a shard of 4"),
    ("auto/4", {"JOB_COMPLETION_INDEX": "-1"}, "not a whole number"),
    ("auto", {"CI_NODE_INDEX": "3", "CI_NODE_TOTAL": "2"}, "not a shard of 2"),
    ("auto", {"CI_NODE_INDEX": "1"}, "CI_NODE_TOTAL is not set"),
    ("auto/3", {"CI_NODE_INDEX": "1", "CI_NODE_TOTAL": "2"}, "CI_NODE_TOTAL=2"),
])
def test_auto_shard_without_a_usable_environment_is_refused(spec, env, says):
    with pytest.raises(ValueError, match=says):
        shard_from_environment(parse_shard(spec), env)


def test_auto_shard_parses_and_keeps_plain_shards():
    assert parse_shard("auto") == AutoShard() and parse_shard("auto/7") == AutoShard(7)
    assert parse_shard("3/7") == Shard(3, 7)


def test_auto_shards_of_a_kubernetes_job_merge_to_the_whole_run(library, whole, tmp_path):
    results = []
    for index in range(3):
        shard = affinity(library, "check", "--no-cache", "--shard", "auto", "--format", "json", ".",
                         env={"JOB_COMPLETION_INDEX": str(index), "AFFINITY_SHARD_COUNT": "3"})
        assert json.loads(shard.stdout)["shard"]["index"] == index + 1
        (tmp_path / f"{index}.json").write_text(shard.stdout)
        results.append(str(tmp_path / f"{index}.json"))
    merged = affinity(library, "merge", *results, "--format", "json")
    assert (merged.returncode, merged.stdout) == (whole.returncode, whole.stdout)


def test_auto_shard_without_a_farm_is_one_line_and_exit_2(library):
    result = affinity(library, "check", "--shard", "auto", ".")
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.count("\n") == 1 and "no shard index in the environment" in result.stderr


# --resume ----------------------------------------------------------------------------------------------------


def _killed_mid_run(folder: Path, journal: Path, *args: str, after_lines: int) -> None:
    """Start ``check --resume journal ARGS`` and SIGKILL it once the journal holds ``after_lines`` lines."""
    process = subprocess.Popen([*CLI, "check", "--no-cache", "-j", "1", "--resume", str(journal), *args, "."],
                               cwd=folder, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and process.poll() is None:
        if journal.exists() and journal.read_bytes().count(b"\n") >= after_lines:
            break
        time.sleep(0.005)
    process.send_signal(signal.SIGKILL)
    process.wait()


def test_a_killed_shard_rerun_with_resume_gives_the_whole_run(library, whole, tmp_path):
    journals = [tmp_path / f"shard{k}.jsonl" for k in (1, 2)]
    _killed_mid_run(library, journals[0], "--shard", "1/2", after_lines=6)
    lines_before = journals[0].read_bytes().count(b"\n")
    assert 1 < lines_before < 23, "the kill came before the shard's end"
    rerun = affinity(library, "check", "--no-cache", "--shard", "1/2", "--resume", str(journals[0]),
                     "--progress", "json", "--format", "json", ".")
    progress = [json.loads(line) for line in rerun.stderr.splitlines() if line.startswith("{")]
    header = json.loads(journals[0].read_text().splitlines()[0])
    assert progress[-1]["total"] == header["files"] - (lines_before - 1)  # only the files not yet in it
    affinity(library, "check", "--no-cache", "--shard", "2/2", "--resume", str(journals[1]), ".")
    merged = affinity(library, "merge", *map(str, journals), "--format", "json")
    assert (merged.returncode, merged.stdout) == (whole.returncode, whole.stdout)
    # The resumed shard's own output is the unbroken shard's.
    unbroken = affinity(library, "check", "--no-cache", "--shard", "1/2", "--format", "json", ".")
    assert rerun.stdout == unbroken.stdout


def test_a_partial_last_line_is_cut_off_and_its_file_checked_again(library, whole, tmp_path):
    journal = tmp_path / "run.jsonl"
    first = affinity(library, "check", "--no-cache", "--resume", str(journal), "--format", "json", ".")
    lines = journal.read_bytes().splitlines(keepends=True)
    assert first.stdout == whole.stdout and len(lines) == 43
    journal.write_bytes(b"".join(lines[:20]) + lines[20][:17])  # a kill mid-write
    again = affinity(library, "check", "--no-cache", "--resume", str(journal), "--progress", "json",
                     "--format", "json", ".")
    assert again.stdout == whole.stdout
    progress = [json.loads(line) for line in again.stderr.splitlines() if line.startswith("{")]
    assert progress[-1]["done"] == 23
    rewritten = journal.read_bytes().splitlines(keepends=True)
    assert rewritten[:20] == lines[:20] and all(line.endswith(b"}\n") for line in rewritten)


@pytest.mark.parametrize(("change", "says"), [
    (lambda lines: lines[:5] + [b"{not json\n"] + lines[6:], "line 6: not JSON"),
    (lambda lines: [b'{"schema":"quad-affinity-journal","version":1,"settings":{},"files":3,"run_digest":"x",'
                    b'"shard":null}\n'], "another run"),
    (lambda lines: [b'{"schema":"other"}\n'], "line 1: not an affinity check journal"),
])
def test_a_journal_of_another_run_or_damaged_is_refused_in_one_line(library, tmp_path, change, says):
    journal = tmp_path / "run.jsonl"
    affinity(library, "check", "--no-cache", "--resume", str(journal), ".")
    damaged = change(journal.read_bytes().splitlines(keepends=True))
    journal.write_bytes(b"".join(damaged))
    result = affinity(library, "check", "--no-cache", "--resume", str(journal), ".")
    assert result.returncode == 2 and result.stdout == "", result.stderr
    assert result.stderr.count("\n") == 1 and says in result.stderr
    assert journal.read_bytes() == b"".join(damaged)  # never rewritten


def test_a_journal_of_other_settings_is_refused(library, tmp_path):
    journal = tmp_path / "run.jsonl"
    affinity(library, "check", "--no-cache", "--resume", str(journal), ".")
    result = affinity(library, "check", "--no-cache", "--threshold", "0.8", "--resume", str(journal), ".")
    assert result.returncode == 2 and "written by another run (its settings differ)" in result.stderr


def test_merge_refuses_an_unfinished_journal(library, tmp_path):
    journals = [tmp_path / f"shard{k}.jsonl" for k in (1, 2)]
    for k, journal in enumerate(journals, 1):
        affinity(library, "check", "--no-cache", "--shard", f"{k}/2", "--resume", str(journal), ".")
    journals[1].write_bytes(b"".join(journals[1].read_bytes().splitlines(keepends=True)[:-3]))
    merged = affinity(library, "merge", *map(str, journals))
    assert merged.returncode == 2 and "an unfinished journal" in merged.stderr and "--resume" in merged.stderr


# progress and cache ------------------------------------------------------------------------------------------


def test_json_progress_counts_every_file_and_finding(library, whole):
    result = affinity(library, "check", "--no-cache", "--progress", "json", "-q", ".")
    lines = [json.loads(line) for line in result.stderr.splitlines() if line.startswith("{")]
    summary = json.loads(whole.stdout)["summary"]
    assert lines[0]["done"] == 0 and lines[-1]["done"] == lines[-1]["total"] == summary["files"]
    assert lines[-1]["findings"] == summary["findings"] and lines[-1]["unreadable"] == 1
    assert [line["done"] for line in lines] == sorted(line["done"] for line in lines)
    assert lines[-1]["eta_s"] == 0.0


def test_json_progress_is_throttled_to_a_line_a_second():
    import io

    from affinity.findings import FileReport
    from affinity.pipeline.progress import json_lines

    ticks = iter([0.0, 0.1, 0.2, 1.3, 1.4, 1.5])
    out = io.StringIO()
    results = [(i, FileReport(f"{i}.obj")) for i in range(4)]
    assert list(json_lines(iter(results), 4, out, clock=lambda: next(ticks))) == results
    lines = [json.loads(line) for line in out.getvalue().splitlines()]
    # start (t=0), the first file (t=0.1), the third (t=1.3, a second after the last line), the end (t=1.5)
    assert [line["done"] for line in lines] == [0, 1, 3, 4]
    assert lines[2]["files_per_s"] == pytest.approx(3 / 1.3, rel=1e-3)
    assert lines[2]["eta_s"] == pytest.approx(1 / (3 / 1.3), abs=0.1)


def test_each_shard_keeps_its_own_cache_file(library, tmp_path):
    env = {"AFFINITY_CACHE_DIR": str(tmp_path / "cache")}
    for k in (1, 2):
        affinity(library, "check", "--shard", f"{k}/2", ".", env=env)
    names = sorted(p.name for p in (tmp_path / "cache").glob("*.sqlite"))
    assert len(names) == 2 and names[0].endswith("-shard-1-of-2.sqlite") and names[1].endswith("-shard-2-of-2.sqlite")


def test_a_journal_behind_a_link_is_refused_and_its_target_unchanged(library, tmp_path):
    target = tmp_path / "elsewhere.txt"
    target.write_text("keep me\n")
    (tmp_path / "run.jsonl").symlink_to(target)
    result = affinity(library, "check", "--no-cache", "--resume", str(tmp_path / "run.jsonl"), ".")
    assert result.returncode == 2 and "is a symbolic link" in result.stderr and result.stderr.count("\n") == 1
    assert target.read_text() == "keep me\n"
