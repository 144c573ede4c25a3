"""`roughfe validate`: output-folder ownership, summary, exit status, a study that raises.

The studies are stand-in scripts in a temporary validation/ folder (the real ones take
minutes); they check what the command promises around them.
"""
import json

import pytest

from roughfe.cli import main, validate_cmd

MET = '''"""Stand-in study whose target is met."""
import json


def main(outdir, quick=False):
    # the folder is owned while the study runs
    assert (outdir / "UNFINISHED").is_file()
    (outdir / "alpha.json").write_text(json.dumps({"targets": [
        {"name": "alpha: x", "target": "<= 1", "measured": "0.5", "value": 0.5,
         "met": True, "reason": "quick" if quick else "full"}]}))
    return True
'''
MISSED = '''"""Stand-in study whose target is NOT met."""
import json


def main(outdir):
    (outdir / "beta.json").write_text(json.dumps({"targets": [
        {"name": "beta: y", "target": "<= 1", "measured": "2", "value": 2.0,
         "met": False, "reason": "measured"}]}))
    return False
'''
RAISES = '''"""Stand-in study that raises."""


def main(outdir):
    raise RuntimeError("solver diverged at step 3")
'''


@pytest.fixture
def studies(tmp_path, monkeypatch):
    folder = tmp_path / "validation"
    folder.mkdir()
    for name, text in (("alpha", MET), ("beta", MISSED), ("gamma", RAISES)):
        (folder / f"{name}.py").write_text(text)
    monkeypatch.setattr(validate_cmd, "_validation_dir", lambda: folder)
    monkeypatch.setattr(validate_cmd, "VALIDATIONS",
                        {"good": ("alpha",), "bad": ("beta", "gamma")})
    monkeypatch.setattr(validate_cmd, "NOT_QUICK", {"beta"})
    return tmp_path


def test_validate_owns_its_folder_and_reports_every_study(studies, capsys, monkeypatch):
    out = studies / "report"
    assert main(["validate", "good", "--quick", "-o", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["all_met"] and summary["quick"]
    assert summary["validations"]["good"]["targets"][0]["reason"] == "quick"
    assert not (out / "UNFINISHED").exists()
    owner = json.loads((out / ".roughfe-output.json").read_text())
    assert owner["command"] == "validate good" and owner["status"] == "complete"

    # a missed target and a study that raises: exit 1, both reported, the run completes
    assert main(["validate", "all", "-o", str(studies / "all")]) == 1
    summary = json.loads((studies / "all" / "summary.json").read_text())
    rows = {t["name"]: t for v in summary["validations"].values() for t in v["targets"]}
    assert rows["alpha: x"]["met"] and not rows["beta: y"]["met"]
    assert not rows["gamma: ran to the end"]["met"]
    assert "solver diverged at step 3" in rows["gamma: ran to the end"]["measured"]
    assert not summary["all_met"] and summary["validations"]["good"]["met"]
    assert set(summary["validations"]["bad"]["cpu_seconds"]) == {"beta", "gamma"}
    assert not (studies / "all" / "UNFINISHED").exists()
    assert "NOT met: beta: y" in capsys.readouterr().out

    # another validation's folder, or foreign files, are refused: exit 2, nothing touched
    capsys.readouterr()
    assert main(["validate", "bad", "-o", str(out)]) == 2
    assert "the output of `roughfe validate good`" in capsys.readouterr().err
    foreign = studies / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep me")
    assert main(["validate", "good", "-o", str(foreign)]) == 2
    assert (foreign / "notes.txt").read_text() == "keep me"
    assert sorted(p.name for p in foreign.iterdir()) == ["notes.txt"]

    # --quick leaves out a script without a reduced case: a "not run" row (met null),
    # never "met"; a validation none of whose scripts ran is not "met" either (it read
    # "all validation targets met" with no row at all)
    capsys.readouterr()
    assert main(["validate", "bad", "--quick", "-o", str(studies / "q")]) == 1
    summary = json.loads((studies / "q" / "summary.json").read_text())
    rows = {t["name"]: t for t in summary["validations"]["bad"]["targets"]}
    assert rows["beta: not run"]["met"] is None and "without --quick" in rows[
        "beta: not run"]["reason"]
    assert summary["not_run"] == ["beta"] and not summary["all_met"]
    assert "not run: beta" in capsys.readouterr().out
    monkeypatch.setattr(validate_cmd, "NOT_QUICK", {"alpha"})
    assert main(["validate", "good", "--quick", "-o", str(studies / "q2")]) == 0
    summary = json.loads((studies / "q2" / "summary.json").read_text())
    assert summary["validations"]["good"]["met"] is None and not summary["all_met"]
    assert "nothing validated: no reduced case in alpha" in capsys.readouterr().out
    monkeypatch.setattr(validate_cmd, "NOT_QUICK", {"beta"})

    # the same validation again replaces its own earlier output
    (out / "alpha.json").write_text("{}")
    assert main(["validate", "good", "-o", str(out)]) == 0
    assert json.loads((out / "summary.json").read_text())["quick"] is False
    assert json.loads((out / "alpha.json").read_text())["targets"][0]["reason"] == "full"
