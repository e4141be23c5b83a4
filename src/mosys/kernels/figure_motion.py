"""Rod endpoints over a whole trajectory, from a generated module's ``endpoints_into``."""

from __future__ import annotations

from numba import njit, types

ENDPOINTS_INTO = types.FunctionType(types.void(types.float64[::1], types.float64[:, :, ::1]))


@njit(types.void(ENDPOINTS_INTO, types.float64[:, ::1], types.float64[:, :, :, ::1]), cache=True)
def endpoints_over_time(endpoints_into, coordinates, out):
    """Rod endpoints for every sample. coordinates: (N, n) q, SI; out: (N, n_rods, 2, 2) m."""
    for sample in range(coordinates.shape[0]):
        endpoints_into(coordinates[sample], out[sample])
