"""Print the tach-TSA amplitude error per order (issue 17.8); not a test, a measurement:

    python3 tests/diagnostics/tach_tsa_errors.py

Same record as tests/diagnostics/test_tsa_tach_accuracy.py (5 % speed swing, order 69 at 0.1 fs
at the fastest speed, 1 pulse per revolution), for a square key-phasor sampled without an
anti-alias filter and for the same pulse through an ideal anti-alias low-pass at 0.45 fs, with
the former 4-point and the current 6-point resampler.
"""

import sys
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
import test_tsa_tach_accuracy as T  # noqa: E402

from geardyn.diagnostics import tach_pulse_times, tsa  # noqa: E402

warnings.simplefilter("ignore")
t, theta, x, tach, square, rise = T.record.__wrapped__()
edges = {"square pulse (no AA filter)": tach_pulse_times(square, fs=T.FS),
         "band-limited pulse (DAQ AA)": tach_pulse_times(tach, fs=T.FS, threshold=2.5)}
print(f"order 69 at {69 * T.F_ROT / T.FS:.4f} fs at the mean speed, 0.1 fs at the fastest")
for label, e in edges.items():
    for taps in (4, 6):
        amp, _ = T._order_errors(tsa(x, fs=T.FS, tach_times=e, samples_per_rev=512,
                                     interp_points=taps))
        print(f"{label:28s} {taps}-point resampler:",
              "  ".join(f"order {k}: {v:+.2e}" for k, v in amp.items()))
