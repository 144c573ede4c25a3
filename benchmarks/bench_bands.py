"""Speed of band-chromosome mechanics on a measured surface (issue 15 §4).

Target (issue 15): the chromosome mechanics of a 256^2 measured surface (every TD and BU
partial sum, 20 steps each) in < 2 min on 2 cores. The measured file di-1.di (512^2,
AFM) is strided to 256^2, plane-detrended and decomposed into sqrt(2) bands (DCT, the
window is not periodic); every chromosome, TD and BU sum is loaded in 20 approaches with
the non-periodic (Love, DC-FFT) BEM. Wall and process CPU times are printed with the load
average (the machine may be shared). Run: .venv/bin/python benchmarks/bench_bands.py [N]
"""
import os
import sys
import time
from pathlib import Path

from roughfe.genomics.band_mechanics import band_mechanics
from roughfe.genomics.bands import band_chromosomes
from roughfe.surfaces.io import load_surface
from roughfe.surfaces.surface import Surface

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "topographies" / "di-1.di"
TARGET_S = 120.0


def main(n=256):
    if not DATA.is_file():
        print(f"measured file not found: {DATA}; skipped")
        return 0
    s = load_surface(DATA)
    stride = max(1, s.shape[0] // n)
    h = s.heights[::stride, ::stride][:n, :n]
    surf = Surface(h, (h.shape[0] * s.spacing[0] * stride, h.shape[1] * s.spacing[1] * stride))
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; {DATA.name} "
          f"-> {surf.shape}")
    t0, c0 = time.perf_counter(), time.process_time()
    bands = band_chromosomes(surf)
    t_dec = time.perf_counter() - t0
    mech = band_mechanics(bands, youngs_modulus=1e9, poisson=0.3, n_steps=20)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"{bands.n_chromosomes} bands, decomposition {t_dec:.2f} s; {mech.nit} sweeps of 20 "
          f"steps: wall {wall:.1f} s, cpu {cpu:.1f} s ({wall / mech.nit:.2f} s per sweep)")
    met = wall < TARGET_S
    print(f"target < {TARGET_S:.0f} s wall on 2 cores: {'met' if met else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(*(int(a) for a in sys.argv[1:2])))
