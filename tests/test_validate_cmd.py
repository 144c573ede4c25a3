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


SKIPS = '''"""Stand-in study with a met target, a row reported beside the targets and a target
that did not run (an optional tool missing)."""
import json


def main(outdir):
    (outdir / "delta.json").write_text(json.dumps({"targets": [
        {"name": "delta: z", "target": "<= 1", "measured": "0.5", "value": 0.5,
         "met": True, "reason": ""},
        {"name": "delta: cost", "target": "reported", "measured": "3 s", "value": 3.0,
         "met": None, "reason": "cost: reported, not a target"},
        {"name": "delta: vs the other code: not run", "target": "<= 1 %",
         "measured": "not run", "value": None, "met": None,
         "reason": "the other code is not importable"}]}))
    return True
'''


def test_a_target_that_did_not_run_is_named_and_never_all_met(studies, capsys,
                                                                monkeypatch):
    """A skipped target row (roughfe.validation.skipped) is printed as not run, listed in
    summary.json's not_run and makes all_met false (exit 0: nothing is NOT met); a row
    reported beside the targets is neither. Before, the run said "all validation targets
    met" and all_met was true."""
    (studies / "validation" / "delta.py").write_text(SKIPS)
    monkeypatch.setattr(validate_cmd, "VALIDATIONS", {"skips": ("delta",)})
    out = studies / "skips"
    assert main(["validate", "skips", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "all validation targets met" not in text
    assert "not run: delta: vs the other code (the other code is not importable)" in text
    assert "not run: delta: delta: vs the other code" in text.splitlines()[-1]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["not_run"] == ["delta: delta: vs the other code"]
    assert summary["validations"]["skips"]["met"] is True and not summary["all_met"]


def _script(name):
    """A real script of validation/ (its cases are replaced by the test)."""
    return validate_cmd._load(name)


def test_bem_validation_without_tamaas_says_the_tamaas_target_did_not_run(
        tmp_path, capsys, monkeypatch):
    """validation/bem_contact.py with tamaas not importable (its cases replaced by
    instant stand-ins): the Tamaas row is a skipped target, so `validate bem` names it
    and summary.json is not all met (it said "all validation targets met", all_met true)."""
    bem = _script("bem_contact")
    row = {"n": 1024, "s": 1, "A": 0.5, "A_ref": 0.5, "width_err": 1e-4,
           "edge_width_err": 1e-5, "gap_err": 1e-5, "nit": 3, "solver": "pk",
           "radius_err": 1e-4, "load_err": 1e-4, "peak_err": 1e-4, "stiffness_err": 1e-4,
           "time_s": 0.1, "seed": 0, "periodic": True, "max_rel_diff": 1e-12, "nit_pk": 3}
    for case, n in (("westergaard_cases", 1024), ("hertz_cases", 256),
                    ("line_cases", 2048), ("solver_cases", 32)):
        monkeypatch.setattr(bem, case, lambda *a, n=n: [{**row, "n": n}])
    monkeypatch.setattr(bem, "tamaas_case", lambda: None)
    monkeypatch.setattr(bem, "_figure", lambda w, path: path)
    monkeypatch.setattr(validate_cmd, "_load", lambda script: bem)
    out = tmp_path / "bem"
    assert main(["validate", "bem", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "all validation targets met" not in text
    assert "not run: A* and mean gap vs Tamaas" in text
    summary = json.loads((out / "summary.json").read_text())
    assert not summary["all_met"]
    assert summary["not_run"] == ["bem_contact: A* and mean gap vs Tamaas 2.8 (256^2)"]
    assert "**not run**" in (out / "bem_contact.md").read_text()


def test_fem_validation_without_mpirun_keeps_the_mpi_target_as_not_run():
    """validation/bem_vs_fem.py: with no mpirun the MPI comparison is a skipped row (it
    was dropped from the targets, so nothing said the check had not run)."""
    from roughfe.validation import is_skipped
    bem_vs_fem = _script("bem_vs_fem")
    west = {"max_width_error_fem": 1e-3, "max_width_error_bem": 1e-3, "n_nodes": 129,
            "mean_gap_error_fem": 1e-3, "mean_gap_error_bem": 1e-5, "stiffness_error_fem": 1e-3,
            "stiffness_error_bem": 1e-3, "pressure_fem_over_bem": [4e-4, 5e-4]}
    rows = bem_vs_fem.target_rows(west, {}, {"ok": None, "note": "mpirun not found"})
    assert [r.name for r in rows if is_skipped(r)] == [
        "FEM-VI: 2 MPI ranks vs serial (p, A*, K): not run"]
    ran = bem_vs_fem.target_rows(west, {}, {"ok": True, "max_rel_diff": 1e-12})
    assert not any(is_skipped(r) for r in ran) and all(r.met for r in ran)


def test_the_database_cost_row_is_reported_not_met():
    """validation/surface_genomics.py: the database cost has no criterion; its row was
    "met" by a hard-coded True (met even for a NaN cost). It is reported (met null,
    roughfe.validation.reported) and counts neither way."""
    from roughfe.validation import is_skipped
    genomics = _script("surface_genomics")
    rows = genomics._targets(
        rec=[{"M_exact": True, "gene_error": 0.0, "phase_error_rad": 0.0,
              "angle_error_rad": 0.0, "rms_error": 0.0}],
        noise=[{"noise": 0.01, "angle_error_deg": 0.1, "gamma_error": 1e-3,
                "M_exact": True, "misfit_over_noise": 1.0}],
        mech={"a.x3p": {"sum_error": 0.0, "c_td_last": 1.0, "partition": True,
                        "td_last_K_deviation": 0.0, "td_last_A_deviation": 0.0}},
        designs=[], db_info={"n_nodes": 16, "cpu_per_genome_s": float("nan"), "computed": 0},
        x3p={"window": {"series_deviation_max": 0.01, "K_range": [1.0, 2.0],
                        "compliance_m_per_Pa": 1e-9}},
        west={"wave": [2, 1], "n": 256, "eta": 2.0, "one_minus_s_K": 5e-4,
              "one_minus_s_A": 0.04})
    cost = [r for r in rows if r.name.startswith("surface database cost per genome")]
    assert len(cost) == 1 and cost[0].met is None and not is_skipped(cost[0])
    assert "reported, not a target" in cost[0].reason


def test_the_sum_of_all_bands_row_can_fail():
    """validation/surface_genomics.py: the TD sum of all bands is its own sweep (it was the
    complete surface's curve, c_n = 1 by construction). The row fails on a sum whose K is
    off by a factor (c stays 1), on a failed sweep (NaN; min() had skipped it) and on c."""
    genomics = _script("surface_genomics")

    def row(*files):
        mech = {f"{i}.x3p": {"sum_error": 2e-16, "c_td_last": c, "partition": True,
                             "td_last_K_deviation": dk, "td_last_A_deviation": 0.0}
                for i, (c, dk) in enumerate(files)}
        rows = genomics._targets(
            rec=[], noise=[{"noise": 0.01, "angle_error_deg": 0.1, "gamma_error": 1e-3,
                            "M_exact": True, "misfit_over_noise": 1.0}],
            mech=mech, designs=[], db_info={"n_nodes": 16, "cpu_per_genome_s": 1.0,
                                            "computed": 0},
            x3p={"window": {"series_deviation_max": 0.01, "K_range": [1.0, 2.0],
                            "compliance_m_per_Pa": 1e-9}},
            west={"wave": [2, 1], "n": 256, "eta": 2.0, "one_minus_s_K": 5e-4,
                  "one_minus_s_A": 0.04})
        return next(r for r in rows if r.name.startswith("measured files: TD sum"))
    honest = (1.0 - 1.1e-16, 3.2e-10)          # x3p-2 at 47^2, 8 steps (measured)
    assert row(honest, honest).met
    assert not row(honest, (1.0, 1e-3)).met                 # K off by 0.1 %, c = 1
    assert not row((float("nan"), float("nan")), honest).met
    assert not row(honest, (1.0 - 1e-9, 3.2e-10)).met
    assert not row().met                                      # no file measured


def test_fsi_position_control_mean_gaps_are_reported_as_the_docstring_says():
    """validation/fsi_fem.py: under position control the mean gap is fixed by Delta in both
    methods, so its rows are reported (met None) even 5 % apart; under load control they
    are gated. The module's "Targets" paragraph called the position-control mean gaps "within
    1 % at every r" a target; it says now that they are reported, not gated."""
    fsi = _script("fsi_fem")

    def levels(name="forward"):
        one_way = (fsi.one_way_exact(fsi.CASES[name]) if "approach" in fsi.CASES[name]
                   else 1.0)
        out = []
        for r in fsi.LEVELS:
            bem = {q: 1.0 + 0.1 / r ** 2 for q in fsi.QUANTITIES}
            bem["one_way_leak_rate"] = one_way * (1.0 + 0.01 / r ** 2)
            fem = {q: v * (1.05 if q == "mean_gap" else 1.001) for q, v in bem.items()}
            fem["one_way_leak_rate"] = bem["one_way_leak_rate"]
            out.append({"r": r, "bem": {**bem, "state": "open"},
                        "fem": {**fem, "state": "open"}})
        return out
    position, _ = fsi.case_targets("forward", levels())
    gaps = [r for r in position if "mean gap" in r.name]
    assert len(gaps) == 1 and gaps[0].met is None and "not a target" in gaps[0].reason
    assert all(r.met for r in position if "leak" in r.name)
    load, _ = fsi.case_targets("balanced", levels("balanced"))
    assert [r.met for r in load if "mean" in r.name] == [False, False]
    targets = fsi.__doc__.split("Targets (met / NOT met):")[1]
    assert "at every r" not in targets and "reported" in targets and "not gated" in targets


def test_design_quick_case_docstring_gates_only_its_targets():
    """validation/design_study.quick_case reports the stages' gains over their start (>= 0
    by construction: a stage keeps its start when it does not improve) and gates only the
    reproduced scores; its docstring called "no stage lowers the score of its start" a
    target."""
    study = _script("design_study")
    doc = " ".join(study.quick_case.__doc__.split())
    targets = doc.split("Targets:")[1].split(". ")[0]
    assert "independent BEM" in targets and "lower" not in targets and "gain" not in targets
    assert "gain over the best start is reported, not a target" in doc


def test_the_mpi_row_needs_two_ranks(monkeypatch):
    """validation/bem_vs_fem.mpi_case: when `mpirun -n 2` starts two singletons (each
    COMM_WORLD of size 1) both runs are serial and equal by construction: not met (it was
    met with a difference of 0)."""
    import json
    import shutil
    import subprocess
    from types import SimpleNamespace
    bem_vs_fem = _script("bem_vs_fem")
    seen, launched = [], {"size": 1}       # COMM_WORLD.size of a run under mpirun -n 2

    def run(cmd, **kw):
        seen.append(cmd)
        line = json.dumps({"p": [1.0, 2.0], "A": [0.1, 0.2], "K": [3.0, 4.0],
                           "ranks": launched["size"] if "-n" in cmd else 1})
        return SimpleNamespace(returncode=0, stdout=line + "\n", stderr="")
    monkeypatch.setattr(shutil, "which", lambda name: "/usr/bin/mpirun")
    monkeypatch.setattr(subprocess, "run", run)
    single = bem_vs_fem.mpi_case()
    assert single["ok"] is False and "not a parallel run" in single["note"]
    assert "-n" in seen[-1] and "2" in seen[-1]
    launched["size"] = 2
    two = bem_vs_fem.mpi_case()
    assert two["ok"] is True and two["max_rel_diff"] == 0.0
    row = bem_vs_fem.target_rows({"max_width_error_fem": 1e-3, "max_width_error_bem": 1e-3,
                                  "n_nodes": 129, "mean_gap_error_fem": 1e-3,
                                  "mean_gap_error_bem": 1e-5, "stiffness_error_fem": 1e-3,
                                  "stiffness_error_bem": 1e-3,
                                  "pressure_fem_over_bem": [4e-4, 5e-4]}, {}, single)[-1]
    assert row.met is False and "not a parallel run" in row.reason


def test_no_validation_row_is_met_by_a_constant():
    """No target row of validation/*.py is built with met = True (or False) typed in: a
    verdict must come from a measured value (a number with no criterion is reported)."""
    import ast
    bad = []
    for path in sorted(validate_cmd._validation_dir().glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not (isinstance(node, ast.Call) and getattr(node.func, "id", "") in
                    ("Target", "_row")):
                continue
            met = node.args[3] if len(node.args) > 3 else next(
                (k.value for k in node.keywords if k.arg == "met"), None)
            if isinstance(met, ast.Constant) and isinstance(met.value, bool):
                bad.append(f"{path.name}:{node.lineno}")
    assert not bad, f"rows with a constant met: {bad}"


CTRL_C = '''"""Stand-in study the user interrupts (Ctrl-C)."""


def main(outdir):
    raise KeyboardInterrupt()
'''


def test_ctrl_c_keeps_the_reports_already_finished(studies, capsys, monkeypatch):
    """Ctrl-C during `validate all`: exit 130, the finished study's report stays with
    UNFINISHED and the status "interrupted" (the folder the run had created was removed,
    finished reports and all)."""
    (studies / "validation" / "stop.py").write_text(CTRL_C)
    monkeypatch.setattr(validate_cmd, "VALIDATIONS", {"good": ("alpha",), "stop": ("stop",)})
    out = studies / "interrupted"
    assert main(["validate", "all", "-o", str(out)]) == 130
    assert json.loads((out / "alpha.json").read_text())["targets"][0]["met"]
    assert (out / "UNFINISHED").is_file()
    assert json.loads((out / ".roughfe-output.json").read_text())["status"] == "interrupted"


PROBE = '''"""Stand-in study that reads summary.json while it runs: what a kill would leave."""
import json


def main(outdir):
    seen = json.loads((outdir / "summary.json").read_text())
    (outdir / "probe.json").write_text(json.dumps({"seen": seen, "targets": [
        {"name": "probe: p", "target": "<= 1", "measured": "0", "value": 0.0, "met": True,
         "reason": ""}]}))
    return True
'''


def test_a_killed_run_never_leaves_an_all_met_summary(studies, monkeypatch):
    """summary.json while the second of two validations runs (what SIGKILL leaves): the
    planned list, complete false, all_met false (it read {"all_met": true} with only the
    first study in it); at the end complete and all met."""
    (studies / "validation" / "probe.py").write_text(PROBE)
    monkeypatch.setattr(validate_cmd, "VALIDATIONS", {"good": ("alpha",), "probe": ("probe",)})
    out = studies / "killed"
    assert main(["validate", "all", "-o", str(out)]) == 0
    seen = json.loads((out / "probe.json").read_text())["seen"]
    assert seen["all_met"] is False and seen["complete"] is False
    assert seen["planned"] == ["good", "probe"] and seen["pending"] == ["probe"]
    assert list(seen["validations"]) == ["good"] and seen["validations"]["good"]["met"]
    final = json.loads((out / "summary.json").read_text())
    assert final["complete"] and final["all_met"] and final["pending"] == []


def test_a_quick_report_says_in_its_first_line_that_it_is_the_reduced_case():
    """roughfe.validation.report_title: the first line of every report written with
    quick=True says it is the reduced case (the quick reports of fsi, leakage and
    sequencing never said so), and every script with a reduced case uses it."""
    import ast
    from roughfe.validation import report_title
    full = report_title("Leakage", False)
    quick = report_title("Leakage", True, "one seed")
    assert full == "# Leakage\n" and "reduced" not in full
    assert "reduced case" in quick.splitlines()[0] and "one seed" in quick
    missing = []
    for path in sorted(validate_cmd._validation_dir().glob("*.py")):
        tree = ast.parse(path.read_text())
        main_ = next((n for n in tree.body if isinstance(n, ast.FunctionDef)
                      and n.name == "main"), None)
        if main_ is None or "quick" not in [a.arg for a in main_.args.args]:
            continue
        if not any(isinstance(n, ast.Call) and getattr(n.func, "id", "") == "report_title"
                   for n in ast.walk(tree)):
            missing.append(path.name)
    assert not missing, f"reports with a reduced case that do not say so: {missing}"


def test_the_reduced_sequencing_report_leaves_out_what_it_did_not_compute():
    """validation/genomics_sequencing.py in quick mode wrote the headings (iii) and (iv)
    with nothing under them and named mechanics_*.png figures it had not written."""
    seq = _script("genomics_sequencing")
    assert seq.measured_section({}) == [] and seq.mechanics_section({}) == []
    mech = {"strip": {"sweeps": 3, "time_s": 1.0, "c_td": {"K": [0.5, 1.0]},
                      "c_bu": {"K": [0.2, 1.0]}}}
    text = "\n".join(seq.mechanics_section(mech))
    assert "## (iv)" in text and "mechanics_correlations_*.png" in text
    text = "\n".join(seq.measured_section({"plu-1.plu": {"skipped": "not found"}}))
    assert "## (iii)" in text and "plu-1.plu: skipped" in text


def test_the_leakage_figure_names_the_surface_it_used():
    """validation/leakage_flow.py typed "RMD m=7, D=2.3" as the FE-vs-FV figure title
    while the quick run used m = 6: the title, like the section headings, is built from
    the values used (rmd_label)."""
    leak = _script("leakage_flow")
    assert leak.rmd_label(6) == f"RMD m = 6, D = {leak.ROUGH_D:g}"
    source = (validate_cmd._validation_dir() / "leakage_flow.py").read_text()
    assert "RMD m=7" not in source and 'set_title(f"{rmd_label(m_rough)}' in source


def test_the_one_line_help_is_the_first_sentence_not_the_first_line():
    # "Roughness design study (thesis Chapter 4): macro/micro roughness of the Table 1
    # case," was cut at the docstring's first line break
    from roughfe.cli.validate_cmd import _first_sentence
    doc = "Genome sequencing (thesis Sec. 3.3-3.4): Table 1\nrecovery over seeds. Then more.\n\nX."
    assert _first_sentence(doc) == "Genome sequencing (thesis Sec. 3.3-3.4): Table 1 recovery over seeds"
