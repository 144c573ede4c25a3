"""Result files of a contact sweep, written atomically (roughfe.writers).

One schema for every method: the sweep is a :class:`roughfe.model.SweepResult` from the
BEM or the FEM (:func:`roughfe.response.response`).

* ``results.json``: ``{"inputs": {...}, "steps": [...], "derived": {...}}``, one record
  per step with the keys :data:`roughfe.model.RECORD_KEYS` in SI units, followed by the
  optional numbers a method sets (FEM: ``delta_applied``, ``layer_compliance``), see
  :meth:`SweepResult.to_records`; ``derived`` holds the method, the sweep-level
  dimensionless curves, the units and the references, and for a non-periodic BEM sweep
  (a measured window) the window's bulk compliance ``window_compliance`` C (m/Pa),
  ``bulk_share`` C p/Delta and ``stiffness_compliance`` K C per step
  (:func:`roughfe.bem.window.window_report`, which warns when K C > 0.5 at the largest
  load: K is then mostly the window's flat-punch bulk stiffness).
* ``fields.h5``: datasets ``pressure`` (Pa) and ``gap`` (m) of shape
  ``(frame, *grid)``, ``contact`` (bool) and ``delta`` (m) per frame, with the grid
  size/spacing as attributes (the "frame" layout of Tamaas/ContactMechanics dumps);
  :func:`read_fields_h5` reads it back.
"""
from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from ..errors import FileFormatError
from ..frozen import FrozenMapping
from ..writers import atomic_path, write_json
from ..model import SweepResult
from .window import window_report

#: Units of the step records (dimensionless keys are absent).
UNITS = {"delta": "m", "load": "N (surface) or N/m (profile)", "mean_pressure": "Pa",
         "contact_area": "m^2 (surface) or m (profile)",
         "stiffness": "Pa/m", "stiffness_fd": "Pa/m", "mean_gap": "m",
         "mean_plane_separation": "m", "free_volume": "m^3 (surface) or m^2 (profile)",
         "delta_applied": "m", "layer_compliance": "m/Pa"}


def sweep_document(sweep: SweepResult, inputs: dict) -> dict:
    """The JSON document of a sweep: inputs, per-step records and derived curves (with
    the window's bulk compliance when the sweep is a non-periodic BEM one)."""
    window = window_report(sweep)
    doc = {
        "inputs": dict(inputs),
        "steps": sweep.to_records(),
        "derived": {
            "method": sweep.method, "success": sweep.success,
            "rms_height": sweep.rms_height, "rms_slope": sweep.rms_slope,
            "e_star": sweep.e_star,
            "load_star": [float(x) for x in sweep.load_star],
            "pressure_over_estar_rms_slope": [float(x) for x in sweep.pressure_star],
            "separation_over_sigma": [float(x) for x in sweep.separation_star],
            "units": dict(UNITS),
            "references": list(sweep.results[0].references),
        },
    }
    # two slopes live in one file: name which is which (a user's review: a user who
    # plotted A* against this p/(E* slope) with Persson's curve got another curve than
    # the persson_* columns, which take the PSD's rms gradient)
    doc["derived"]["units"].update(
        rms_height="m", rms_slope="1 (rms slope by finite differences of the heights)",
        pressure_over_estar_rms_slope="1 (p / (E* rms_slope), rms_slope the finite-"
        "difference one above; Persson's columns use persson.rms_gradient, the PSD's)")
    if window:
        doc["derived"].update(window)
        doc["derived"]["units"]["window_compliance"] = "m/Pa"
        # K C can exceed 1 (opd-1: 1.05; a user read it as an error): C is the mean
        # deflection under a uniform pressure, an approximation of the bulk in series
        doc["derived"]["units"]["stiffness_compliance"] = (
            "1 (K C; approximate: C is the window's mean deflection under a uniform "
            "pressure, so K C can exceed 1 slightly)")
    return doc


def write_results_json(path, sweep: SweepResult, inputs: dict):
    """Write ``results.json`` atomically; returns the path."""
    return write_json(path, sweep_document(sweep, inputs))


def write_fields_h5(path, sweep: SweepResult, compression: str = "gzip"):
    """Write pressure and gap of every step to HDF5 (``frame`` first axis), atomically
    (FEM: the values at the top vertices), with each frame's ``delta``, ``mean_pressure``,
    ``stiffness`` (Pa/m; inf at full periodic contact, NaN where not computed),
    ``area_fraction``, ``mean_gap`` and ``unloading`` flag, and the material's ``e_star_Pa``
    as an attribute."""
    import h5py  # Debian's h5py; imported here so the package works without it

    res = sweep.results
    r0 = res[0]
    with atomic_path(path, suffix=".h5") as tmp:
        with h5py.File(tmp, "w") as f:
            f.attrs["size_m"] = np.asarray(r0.size)
            f.attrs["spacing_m"] = np.asarray(r0.spacing)
            f.attrs["periodic"] = bool(r0.periodic)
            f.attrs["method"] = r0.method
            f.attrs["kernel"] = r0.kernel or ""          # none for the FEM
            f.attrs["dimensions"] = json.dumps(["frame"] + ["x", "y"][: r0.pressure.ndim])
            names = [("pressure", "Pa"), ("gap", "m"), ("contact", "1")]
            if all(r.plastic_displacement is not None for r in res):
                names.append(("plastic_displacement", "m"))      # BEM with a hardness
            for name, unit in names:
                data = np.stack([getattr(r, name) for r in res])
                ds = f.create_dataset(name, data=data, compression=compression)
                ds.attrs["unit"] = unit
            ds = f.create_dataset("delta", data=np.array([r.delta for r in res]))
            ds.attrs["unit"] = "m"
            ds = f.create_dataset("mean_pressure", data=np.array([r.mean_pressure for r in res]))
            ds.attrs["unit"] = "Pa"
            # self-contained: the material and the response of every frame beside the
            # fields (results.json holds the same numbers with Persson's theory)
            f.attrs["e_star_Pa"] = float(sweep.e_star)
            for name, unit in (("stiffness", "Pa/m"), ("area_fraction", "1"),
                               ("mean_gap", "m")):
                ds = f.create_dataset(name, data=np.asarray(getattr(sweep, name), float))
                ds.attrs["unit"] = unit
            if getattr(sweep, "unloading", None) is not None:
                ds = f.create_dataset("unloading", data=np.asarray(sweep.unloading, float))
                ds.attrs["unit"] = "1 on the unloading branch, 0 on loading"
    return path


@dataclass(frozen=True, eq=False)
class ContactFields:
    """A ``fields.h5`` read back (:func:`read_fields_h5`).

    Attributes
    ----------
    data : Mapping[str, ndarray]
        Every dataset by name, read-only: ``pressure`` (Pa), ``gap`` (m), ``contact`` of
        shape ``(frame, *grid)``, and ``delta``, ``mean_pressure``, ``stiffness``,
        ``area_fraction``, ``mean_gap`` (and ``plastic_displacement``, ``unloading`` when
        written) as written by :func:`write_fields_h5`.
    units : Mapping[str, str]
        The ``unit`` attribute of each dataset.
    attrs : Mapping[str, object]
        The file's attributes (``size_m``, ``spacing_m``, ``periodic``, ``method``,
        ``kernel``, ``dimensions``, ``e_star_Pa``).
    """

    data: FrozenMapping
    units: FrozenMapping
    attrs: FrozenMapping

    def __getitem__(self, name):
        return self.data[name]


def read_fields_h5(path) -> ContactFields:
    """Read a ``fields.h5`` of :func:`write_fields_h5` (``roughfe contact``) back: the
    datasets as read-only arrays with their units, and the file's attributes. A file
    that is not such a file is a :class:`~roughfe.errors.FileFormatError` naming what is
    missing."""
    import h5py

    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise FileFormatError(f"{path} is not an HDF5 file of roughfe contact fields "
                              f"({exc})") from None
    with f:
        missing = [k for k in ("pressure", "gap", "delta") if k not in f]
        if missing:
            raise FileFormatError(f"{path}: no dataset {', '.join(missing)}: not a fields.h5 "
                                  f"of roughfe contact (datasets: {', '.join(f) or 'none'})")
        data, units = {}, {}
        for name, ds in f.items():
            arr = ds[()]
            arr.setflags(write=False)
            data[name] = arr
            units[name] = str(ds.attrs.get("unit", ""))
        attrs = {k: (v.tolist() if isinstance(v, np.ndarray) else
                     v.item() if isinstance(v, np.generic) else v)
                 for k, v in f.attrs.items()}
    return ContactFields(FrozenMapping(data), FrozenMapping(units), FrozenMapping(attrs))
