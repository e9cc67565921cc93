"""The machine formats written a column at a time (``affinity/output/rows.py``) against second implementations.

The rows of JSON, JUnit and SARIF are laid out in byte grids, numbers converted
a column at a time and the SARIF fingerprints' value tokens numbered from sorted
neighbours. Each is checked here against what Python writes one value at a time
(``%d``, ``repr``, ``%.4g``, ``%.6g``), against the ``json`` module re-encoding
the whole document, against ElementTree reading the JUnit XML back, and against
fingerprints recomputed by a plain loop, on the real meshes of ../shared/meshes.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from affinity.output import CheckRun, file_findings, finding_dict, rows, value_token
from affinity.output import json as json_output
from affinity.output.junit import write as write_junit
from affinity.output.sarif import token_ids
from affinity.output.sarif import write as write_sarif
from affinity.pipeline.check import check_files
from affinity.rules import RULES
from affinity.rules.docs import with_unit
from affinity.settings import Settings


def test_integers_are_written_as_percent_d_writes_them():
    numbers = np.concatenate([np.random.default_rng(3).integers(-10**9, 10**9, 5000),
                              [0, 1, 9, 10, 99, 100, -1, -10, 2**40, 7, 7]])
    assert rows.assemble([rows.integers(numbers), b","]) == "".join(f"{n}," for n in numbers.tolist())
    assert rows.assemble([rows.integers(np.full(4, 12)), b","]) == "12," * 4  # one number throughout


def test_floats_are_written_as_repr_and_percent_g_write_them():
    rng = np.random.default_rng(4)
    values = [*(rng.random(3000) * 10.0 ** rng.integers(-30, 30, 3000)).tolist(),
              0.0, -0.0, 5e-324, 1e300, float("inf"), float("-inf"), float("nan"), 0.1, 1e16, 123456789.0]
    for spec in ("%r", "%.4g", "%.6g"):
        assert rows.assemble([rows.floats(values, spec), b";"]) == "".join(spec % v + ";" for v in values)
    assert rows.assemble([rows.floats([-2.2250738585072014e-308, -1.7976931348623157e308], "%r"), b";"]) == (
        "-2.2250738585072014e-308;-1.7976931348623157e+308;")  # the longest texts fill the slot


def test_texts_keep_their_spaces_and_non_ascii_characters():
    texts = ["a b", "", "caf\u00e9 \u2192 x", "  lead", "<&>"]
    assert rows.assemble([b"[", rows.formatted(texts, "%s"), b"]"]) == "".join(f"[{t}]" for t in texts)
    assert rows.assemble([rows.choice(np.array([2, 0, 1, 0]), ["error", "warning", "info"]), b" "]) == (
        "info error warning error ")


def test_token_ids_are_equal_exactly_where_the_value_tokens_are():
    """Dense sampling around the 6th digit's rounding ties and the ends of a decade, and the special values."""
    rng = np.random.default_rng(5)
    base = np.round(rng.random(20000) * 100, 4)
    ties = np.array([float(f"{d}5e{e}") for d in (10000, 12345, 99999, 54321) for e in range(-8, 8)])
    values = np.concatenate([
        base, base * (1 + rng.normal(0, 3e-6, len(base))), -base[:500], ties, np.nextafter(ties, 0),
        np.nextafter(ties, np.inf), [0.0, -0.0, np.nan, np.nan, np.inf, -np.inf, 1e-320, -1e-320, 5e-324,
                                     999999.5, 1e6, 999999.4999999, 1.0, 10.0, 9.999995, 9.9999949999]])
    ids = token_ids(values).tolist()
    tokens = [value_token(v) for v in values.tolist()]
    assert len(set(zip(ids, tokens))) == len(set(ids)) == len(set(tokens))


@pytest.fixture(scope="module")
def shared_run(shared_meshes) -> CheckRun:
    """Every shared OBJ mesh (the textured Spot included), checked with the default settings, paths relative to
    the working directory as a user passes them."""
    paths = sorted(shared_meshes.rglob("*.obj"))
    settings = Settings()
    reports = check_files([(os.path.relpath(p), settings) for p in paths], jobs=1)
    assert sum(r.n_findings for r in reports) > 5000
    return CheckRun(reports, settings, run_cap=10**9)


def _written(write, run: CheckRun) -> str:
    out = io.StringIO()
    write(run, out)
    return out.getvalue()


def test_json_is_what_the_json_module_writes_for_the_same_findings(shared_run):
    text = _written(json_output.write, shared_run)
    document = json.loads(text)
    assert json.dumps(document, separators=(",", ":")) + "\n" == text  # numbers and escapes as json writes them
    expected = []
    for report in shared_run.reports:
        for finding in file_findings(report)[0]:
            measure = shared_run.settings.measure_of(finding.code)
            expected.append({**finding_dict(finding), **({} if measure is None else {"measure": measure})})
    assert document["findings"] == expected


def test_junit_cases_read_back_are_the_findings(shared_run):
    """Each testcase, read by ElementTree, names its finding's rule and face, fails exactly for errors and carries
    the finding's text line, here written one finding at a time from the JSON finding."""
    findings = json.loads(_written(json_output.write, shared_run))["findings"]
    cases = [case for case in ET.fromstring(_written(write_junit, shared_run)).iter("testcase")
             if case.get("name") != "affinity check"]
    assert len(cases) == len(findings)
    for case, f in zip(cases, findings):
        assert (case.get("classname"), case.get("file"), case.get("name"), case.get("line")) == (
            f["path"], f["path"], f"{f['code']} {f['name']} face {f['face']}", str(f["line"]))
        failure, quiet = case.find("failure"), case.find("system-out")
        assert (failure is not None, quiet is not None) == (f["level"] == "error", f["level"] != "error")
        if f.get("texture") is None:
            against = "" if f["threshold"] is None else f" vs {f['threshold']:.4g}"
            measured = with_unit(f"{f['value']:.4g}{against}", f["unit"])
            assert (failure if failure is not None else quiet).text == (
                f"{f['path']}:{f['line']}:{f['column']}: {f['code']} {f['level']} {f['name']}: {f['message']} "
                f"({measured}) [face {f['face']}]")


def test_sarif_fingerprints_are_those_a_plain_loop_counts(shared_run):
    """Every result's fingerprint: rule, file URI, group, value token and the ordinal among equal ones in file
    order, counted here one finding at a time (the sphere's symmetric quads share values, so ordinals reach past 0)."""
    findings = json.loads(_written(json_output.write, shared_run))["findings"]
    log = json.loads(_written(write_sarif, shared_run))
    results = log["runs"][0]["results"]
    assert len(results) == len(findings)
    seen: dict[tuple, int] = {}
    expected = []
    for f, r in zip(findings, results):
        uri = r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
        identity = (f["code"], uri, f["group"], value_token(f["value"]))
        ordinal = seen[identity] = seen.get(identity, -1) + 1
        expected.append(hashlib.sha256("\0".join((*identity, str(ordinal))).encode()).hexdigest()[:32])
    assert max(seen.values()) > 0
    assert [r["partialFingerprints"]["quadAffinity/v1"] for r in results] == expected
    assert [(r["ruleId"], r["properties"]["face"], r["properties"]["value"]) for r in results] == [
        (f["code"], f["face"], f["value"]) for f in findings]
    assert all(r["ruleIndex"] == list(RULES).index(r["ruleId"]) for r in results)
