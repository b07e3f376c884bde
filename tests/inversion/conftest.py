"""Toy forward tables for the inversion tests (no YADE, no pyprop8)."""
import numpy as np
import pytest

from pipeline.inversion.table import ForwardTable

DISTANCES = (2.5, 5.0, 10.0, 20.0)
AZIMUTHS = tuple(np.arange(0.0, 360.0, 30.0))
SLICES = (("strike-slip", 90.0, 180.0, 10.0, 6.5), ("thrust", 40.0, 90.0, 10.0, 6.5))


def away_table(members=6, scatter_deg=8.0, seed=0, p_fall=None, distances=DISTANCES):
    """Every column falls away from the source: downfall (strike frame) = node azimuth +
    noise, i.e. along the direction from epicentre to site.  ``p_fall``: per ring (of
    ``distances`` km) the fraction of members that fall (default all)."""
    rng = np.random.default_rng(seed)
    rings = []
    for i, _ in enumerate(distances):
        nodes = []
        for theta in AZIMUTHS:
            cols = []
            for _ in ("drums", "monolithic"):
                n_fall = members if p_fall is None else int(round(p_fall[i] * members))
                cols.append([(theta + rng.normal(0, scatter_deg)) % 360.0
                             if k < n_fall else None for k in range(members)])
            nodes.append(cols)
        rings.append(nodes)
    falls = [rings for _ in SLICES]          # mechanisms alike: the data cannot tell them
    return ForwardTable.toy(SLICES, distances, AZIMUTHS, falls)


def random_table(members=5, seed=3):
    """Falls in random directions with node-dependent probability (no symmetry)."""
    rng = np.random.default_rng(seed)
    falls = [[[[[float(rng.uniform(0, 360)) if rng.uniform() < 0.3 + 0.5 * rng.uniform()
                 else None for _ in range(members)] for _ in range(2)]
               for _ in AZIMUTHS] for _ in DISTANCES] for _ in SLICES]
    return ForwardTable.toy(SLICES, DISTANCES, AZIMUTHS, falls)


@pytest.fixture
def toy_away():
    return away_table()


@pytest.fixture
def toy_random():
    return random_table()


@pytest.fixture
def make_away_table():
    return away_table
