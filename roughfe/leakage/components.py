"""Face-connected components of the open cells of a gap field, and which of them reach
the inlet and the outlet side: the connectivity of the cell-centred finite-volume
Reynolds scheme (:mod:`roughfe.leakage.finite_volume`), of the trapped-fluid pockets
(:mod:`roughfe.leakage.pockets`), of the critical junction
(:mod:`roughfe.leakage.junction`) and of the sealed free volume of the network
(:mod:`roughfe.leakage.network`). Numpy/scipy only (no PETSc), so the network imports
it cheaply; moved here from :mod:`roughfe.leakage.finite_volume` in round 2, session 29."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy import ndimage
from scipy.sparse.csgraph import connected_components


def _open_components(open_cells: np.ndarray, periodic: bool):
    """Face-connected components of the open cells (labels 0..k-1 per cell, -1 closed).

    ``scipy.ndimage.label`` (4-connectivity) labels the grid; with periodic side walls the
    components meeting across the seam (column -1 | column 0) are merged on the small
    graph of labels."""
    nl, nt = open_cells.shape
    lab, nlab = ndimage.label(open_cells)      # 0: closed, 1..nlab
    root = np.arange(nlab + 1)
    if periodic and nt > 1:
        seam = open_cells[:, -1] & open_cells[:, 0]
        if seam.any():
            a, b = lab[seam, -1], lab[seam, 0]
            graph = sp.csr_matrix((np.ones(a.size, np.int8), (a, b)),
                                  shape=(nlab + 1, nlab + 1))
            _, root = connected_components(graph, directed=False)
    # compact numbering without the closed label
    used = np.zeros(int(root.max()) + 1, bool)
    used[root[1:]] = True
    new = np.cumsum(used) - 1
    table = np.append(-1, new[root[1:]]).astype(np.int32 if nlab < 2**31 - 1 else np.int64)
    return table[lab]


def components_reaching(open_cells: np.ndarray, *, periodic: bool = False):
    """Open components, and which of them touch the inlet (row 0) and the outlet (last row).

    Flow along axis 0. Returns ``(labels, touches_in, touches_out)``: per-cell component
    label (-1 closed) and boolean arrays indexed by label.
    """
    lab = _open_components(np.asarray(open_cells, bool), periodic)
    nlab = int(lab.max()) + 1 if lab.size and lab.max() >= 0 else 0
    touches_in = np.zeros(nlab, bool)
    touches_out = np.zeros(nlab, bool)
    touches_in[lab[0][lab[0] >= 0]] = True
    touches_out[lab[-1][lab[-1] >= 0]] = True
    return lab, touches_in, touches_out
