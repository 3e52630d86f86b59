"""Synthetic data generators."""

import numpy as np
import pytest

from datasets_synthetic.franke import franke, franke_gradient, franke_grid


def test_franke_known_value_and_gradient_by_central_differences():
    # f(0.5, 0.5) by hand: 0.75e^-3.125 + 0.75e^-(30.25/49+0.55) + 0.5e^-2.125 - 0.2e^-6.5 = 0.32576...
    assert franke(0.5, 0.5) == pytest.approx(0.3257621, abs=5e-7)
    rng = np.random.default_rng(0)
    x, y = rng.random(100), rng.random(100)
    h = 1e-5
    num = np.stack([(franke(x + h, y) - franke(x - h, y)) / (2 * h), (franke(x, y + h) - franke(x, y - h)) / (2 * h)], -1)
    # central difference error <= h^2/6 max|f'''| ~ 1e-10 * 1e3 (third derivatives of the sharp Gaussian)
    assert np.allclose(franke_gradient(x, y), num, atol=1e-6)


def test_franke_grid_shape_and_bad_n():
    z, h = franke_grid(4)
    assert z.shape == (5, 5) and h == 0.25
    with pytest.raises(ValueError, match="positive integer"):
        franke_grid(0)
