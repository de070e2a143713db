"""Generated CAD models (issue 24 item 1): the strategy's models are valid
solids whose topology comes from the B-rep, and it draws every feature class."""

import numpy as np
import pytest
from hypothesis import given, settings

pytest.importorskip("cadquery")

from sr33.validators import mesh_stats  # noqa: E402
from tests import fuzzstats  # noqa: E402
from tests.strategies import FEATURE_CLASSES, cad_models  # noqa: E402


@pytest.mark.parametrize("feature", FEATURE_CLASSES)
def test_generated_models_are_solids_of_their_b_rep_topology(feature):
    """Models drawn for each feature class (primitives, unions, cuts, holes,
    fillets, chamfers, a random rigid motion): one closed, oriented solid
    whose truth mesh has the B-rep's Euler characteristic and genus, and
    the class is drawn (read from the result, not the recipe)."""
    drawn = []

    @settings(max_examples=6)
    @given(cad_models(feature))
    def check(model):
        fuzzstats.count(f"cad model ({feature})")
        s = model.shape
        stats = mesh_stats(s.truth_triangles, s.truth_vertices.shape[0])
        assert (stats.open_edges, stats.overloaded_edges, stats.components) == (0, 0, 1)
        assert stats.euler == s.expected.euler == 2 - 2 * s.expected.genus, model.recipe
        assert s.expected.boundary_loops == 0 and s.expected.orientable
        assert np.isfinite(s.truth_vertices).all()
        drawn.append(model.features)

    check()
    assert sum(feature in f for f in drawn) >= 1, (feature, drawn)
