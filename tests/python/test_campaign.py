"""tetra.campaign against `tetra campaign` (runs.csv byte for byte)."""
import json

import pytest

import tetra

SPEC = {
    "scenarios": ["static"],
    "loop": "open",
    "duration_s": 60,
    "kinds": ["bias"],
    "sizes": {"bias": [0.01]},
    "gyros": [1, 3],
    "onsets_s": [20],
    "seeds": [1],
    "fault_free": True,
}


def test_campaign_equals_the_command(tmp_path, run_cli):
    (tmp_path / "spec.yaml").write_text(json.dumps(SPEC))
    run_cli("campaign", tmp_path / "spec.yaml", "--out", tmp_path / "out", "--no-report", "--jobs", 1)
    result = tetra.campaign(SPEC)
    assert result.csv == (tmp_path / "out" / "runs.csv").read_text()
    assert len(result) == 3 == tetra.campaign_spec(SPEC).runs
    rows = result.rows
    assert list(rows["kind"]) == ["none", "bias", "bias"]
    assert list(rows["outcome"][1:]) == ["right", "right"]
    from_file = tetra.campaign(str(tmp_path / "spec.yaml"), runs=[2])
    assert from_file.csv.splitlines()[1] == result.csv.splitlines()[3]


def test_campaign_errors():
    with pytest.raises(tetra.BadInputError, match="bogus"):
        tetra.campaign_spec({**SPEC, "bogus": 1})
    with pytest.raises(ValueError, match="runs"):
        tetra.campaign(SPEC, runs=[7])
    with pytest.raises(tetra.BadInputError, match="kinds"):
        tetra.campaign_spec({**SPEC, "kinds": ["meteor"]})


def test_campaign_report_equals_the_command(tmp_path, run_cli):
    spec = {**SPEC, "dispersions": {"seed": 7, "unit.arw_factor": {"uniform": [0.9, 1.1]}},
            "requirements": ["wrong_exclusion_rate < 1e-3 at 0.95"]}
    (tmp_path / "spec.yaml").write_text(json.dumps(spec))
    run_cli("campaign", tmp_path / "spec.yaml", "--out", tmp_path / "out", "--jobs", 1)
    result = tetra.campaign(spec)
    assert result.csv == (tmp_path / "out" / "runs.csv").read_text()
    assert result.report == (tmp_path / "out" / "report.md").read_text()
    assert "unit.arw_factor.g1" in result.rows.columns
    assert "## Requirements" in result.report

