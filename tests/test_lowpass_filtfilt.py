"""``seisrack.analysis.peaks.lowpass`` writes out the zero-phase filtering with initial states
computed once per filter; the independent reference is ``scipy.signal.sosfiltfilt`` with the
same Butterworth sections and pad length (Gustafsson-style states, odd extension), which it
must match bit for bit, on every shape the rack path feeds it and on the shortest records."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt

from seisrack.analysis.peaks import lowpass


@pytest.mark.parametrize("shape", [(6001, 1, 1), (6001,), (2,), (3, 2), (27, 3, 2), (28,)])
@pytest.mark.parametrize(("fc", "h"), [(10.0, 0.005), (3.0, 0.01), (49.9, 0.01)])
def test_lowpass_is_sosfiltfilt(shape: tuple, fc: float, h: float) -> None:
    a = np.random.default_rng(len(shape) + shape[0]).standard_normal(shape)
    sos = butter(4, fc, btype="low", fs=1.0 / h, output="sos")
    want = sosfiltfilt(sos, a, axis=0, padlen=min(3 * (2 * sos.shape[0] + 1), shape[0] - 1))
    got = lowpass(a, h, fc)
    assert got.shape == want.shape
    assert np.array_equal(got, want)
    assert np.array_equal(lowpass(a, h, fc), got)  # the cached states are not altered
