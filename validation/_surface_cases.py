"""The measured cases of ``validation/surface_genomics.py``: sequencing recovery over
seeds and under noise (i, ii), the band-chromosome mechanics of the measured files (iii),
the 2D surface database and the K(p), A(p) targets of a measured window (iv). SI units
(m, Pa; CPU times in s). A helper module of the study, not a study of its own.
"""
from __future__ import annotations

import resource
from dataclasses import replace
from pathlib import Path

import numpy as np

from roughfe.errors import InputError
from roughfe.genomics import database as gdb
from roughfe.genomics.band_mechanics import band_macro_micro, band_mechanics
from roughfe.genomics.bands import band_chromosomes
from roughfe.genomics.design import surface_targets, window_compliance
from roughfe.genomics.mechanics import curve_difference
from roughfe.genomics.sequencing import sequence_surfaces
from roughfe.genomics.sequencing.surface_data import resolvable_surface_genome
from roughfe.model import DEFAULT_E
from roughfe.surfaces import Surface
from roughfe.surfaces.io import load_surface, topographies_folder

TOPOGRAPHIES = topographies_folder()
N_SEQ, L1 = 48, 1e-3
NOISE = (0.001, 0.01, 0.03)


def _cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _genome(seed):
    return resolvable_surface_genome(seed, length=L1, n_nodes=N_SEQ)


def _wrapped(a):
    return np.abs(np.angle(np.exp(1j * np.asarray(a))))


def recovery(seeds):
    rows = []
    for seed in seeds:
        g, acq, _ = _genome(seed)
        t0 = _cpu()
        r = sequence_surfaces(acq)
        s = r.genome
        row = {"seed": seed, "success": bool(r.success), "cpu_s": _cpu() - t0,
               "M_exact": bool(s is not None and s.M == g.M)}
        if row["M_exact"]:
            truth = g.phase_columns(np.arange(s.n_first, s.n_last + 1))
            row.update({
                "gene_error": max(abs(s.gamma / g.gamma - 1), abs(s.lambda1 / g.lambda1 - 1),
                                  abs(s.A / g.A - 1), abs(s.H - g.H),
                                  float(np.max(np.abs(s.anisotropy / g.anisotropy - 1)))),
                "angle_error_rad": float(np.max(_wrapped(s.angles - g.angles))),
                "phase_error_rad": float(np.max(_wrapped(s.phases - truth))),
                "rms_error": float(np.max(r.rms_errors))})
        rows.append(row)
    return rows


def noise_table(seeds):
    rows = []
    for level in NOISE:
        for seed in seeds:
            g, acq, rng = _genome(seed)
            noisy = [a.with_heights(a.heights + level * a.heights.std() * rng.normal(size=a.shape))
                     for a in acq]
            r = sequence_surfaces(noisy)
            s = r.genome
            ok = s is not None and s.M == g.M
            rows.append({"noise": level, "seed": seed, "M_exact": bool(ok),
                         "angle_error_deg": float(np.degrees(np.max(_wrapped(s.angles - g.angles))))
                         if ok else None,
                         "gamma_error": abs(s.gamma / g.gamma - 1) if s is not None else None,
                         # the noise as a share of the heights about their plane, the
                         # misfit's denominator (sequence_surfaces' signal_rms)
                         "misfit_over_noise": float(np.max(
                             r.rms_errors * r.signal_rms / (level * np.array(
                                 [a.heights.std() for a in acq])))) if s is not None
                         else None,
                         "success": bool(r.success)})
    return rows


def _thinned(surface, n_max):
    step = [max(1, int(np.ceil(n / n_max))) for n in surface.shape]
    h = surface.heights[::step[0], ::step[1]]
    return Surface(h, (h.shape[0] * surface.spacing[0] * step[0],
                       h.shape[1] * surface.spacing[1] * step[1]), periodic=False,
                   metadata={"thinned_by": step})


def measured_mechanics(names, n_max=96, n_steps=10):
    out = {}
    for name in names:
        path = TOPOGRAPHIES / name
        if not path.is_file():
            out[name] = {"skipped": f"{path} not found"}
            continue
        s = _thinned(load_surface(path), n_max)
        t0 = _cpu()
        bands = band_chromosomes(s, 2 ** 0.5, detrend="plane")
        err = float(np.max(np.abs(bands.chromosomes.sum(axis=0) - bands.surface.heights))
                    / np.ptp(bands.surface.heights))
        mech = band_mechanics(bands, youngs_modulus=DEFAULT_E, n_steps=n_steps)
        mm = band_macro_micro(mech)
        last = mech.td_curves[-1]       # the sum of all bands, its own sweep
        dev = (curve_difference(mech.complete, last) if last is not None
               else {"K": np.nan, "A": np.nan})
        out[name] = {"shape": list(s.shape), "n_bands": int(bands.n_chromosomes),
                     "sum_error": err, "c_td_last": float(mech.c_td["K"][-1]),
                     "td_last_K_deviation": dev["K"], "td_last_A_deviation": dev["A"],
                     "c_chromosome_K": [None if not np.isfinite(v) else float(v)
                                        for v in mech.c_chromosome["K"]],
                     "macro": list(mm.macro), "micro": list(mm.micro),
                     "partition": sorted(mm.macro + mm.micro) == [int(i) for i in bands.indices],
                     "sweeps": int(mech.nit), "cpu_s": _cpu() - t0}
    return out


def surface_database(path: Path, length, n_pairs, n_vectors, n_nodes=64, n_steps=10,
                     hurst_range=(0.5, 1.5)):
    settings = gdb.DatabaseSettings(length=length, n_nodes=n_nodes, youngs_modulus=DEFAULT_E,
                                    n_steps=n_steps, dim=2, top_fraction=0.8)
    design = gdb.SobolDesign(dim=2, n_pairs=n_pairs, n_vectors=n_vectors, n_ridges=3,
                             hurst_range=tuple(hurst_range))
    have = set()
    if path.is_file():
        con = gdb.connect(path)
        try:
            if gdb.read_settings(con) == settings:
                gdb.write_design(con, design)       # InputError: built with another design
                have = set(gdb.labels(con))
        except InputError:
            have = set()
        finally:
            con.close()
        if not have:
            path.unlink()
    todo = [t for t in gdb.sobol_tasks(design) if t["label"] not in have]
    t0 = _cpu()
    records = [gdb.genome_entry_task(**t, **settings.to_dict()) for t in todo]
    cpu = _cpu() - t0
    con = gdb.connect(path, create=True)
    try:
        gdb.write_settings(con, settings)
        gdb.write_design(con, design)
        gdb.insert_records(con, records)
    finally:
        con.close()
    return settings, {"n_genomes": len(have) + len(records), "computed": len(records),
                      "n_nodes": n_nodes, "hurst_range": list(hurst_range),
                      "cpu_s": cpu, "cpu_per_genome_s": cpu / max(len(records), 1)}


def measured_targets(measured, settings):
    """K(p), A(p) targets of a measured window in the designs' periodic setting (the
    evenly mirrored window, :func:`surface_targets` ``boundary="periodic"``), and, as a
    check of why, the window alone on the half-space: its K against the series law
    ``1/K_window = 1/K_periodic + C`` with the window's bulk compliance C."""
    t0 = _cpu()
    tk, ta, curve = surface_targets(measured, settings, name="x3p-2", boundary="periodic")
    cpu = _cpu() - t0
    t0 = _cpu()
    _, _, win = surface_targets(measured, settings, name="x3p-2", boundary="window")
    cpu_window = _cpu() - t0
    c = window_compliance(measured.detrended("plane"), settings.youngs_modulus,
                          settings.poisson)
    # like with like: the mirrored window at the window's own sampling (not the design
    # spacing), read at the window's pressures (it reaches further: 0.8 of full contact)
    t0 = _cpu()
    _, _, full = surface_targets(measured, settings, name="x3p-2", resolution="full")
    cpu_full = _cpu() - t0
    # for the series law the periodic K(p) on 24 steps to 0.95 of full contact, so that
    # reading it at the window's pressures adds no interpolation error of note
    dense = replace(settings, n_steps=24, top_fraction=0.95)
    _, _, fine = surface_targets(measured, dense, name="x3p-2", resolution="full")
    sel = win.pressure <= fine.p_max
    k_per = np.exp(np.interp(np.log(win.pressure[sel]), np.log(fine.pressure),
                             np.log(fine.stiffness)))
    series = 1.0 / (1.0 / k_per + c)
    dev = np.abs(series[1:] / win.stiffness[sel][1:] - 1.0)
    return tk, ta, {"shape": list(measured.shape), "size_m": list(measured.size),
                    "solved_shape": list(tk.metadata["solved_shape"]),
                    "solved_size_m": list(tk.metadata["solved_size_m"]),
                    "p_max": curve.p_max, "A_at_p_max": float(curve.area_fraction[-1]),
                    "K_range": [float(curve.stiffness[0]), float(curve.stiffness[-1])],
                    "cpu_s": cpu,
                    "full_resolution": {"solved_shape": [2 * (n - 1) for n in measured.shape],
                                        "p_max": full.p_max,
                                        "A_at_p_max": float(full.area_fraction[-1]),
                                        "K_range": [float(full.stiffness[0]),
                                                    float(full.stiffness[-1])],
                                        "cpu_s": cpu_full},
                    "window": {"p_max": win.p_max, "A_at_p_max": float(win.area_fraction[-1]),
                               "K_range": [float(win.stiffness[0]), float(win.stiffness[-1])],
                               "compliance_m_per_Pa": c,
                               "series_deviation_max": float(dev.max()),
                               "cpu_s": cpu_window}}
