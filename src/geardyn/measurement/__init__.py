"""The measurement chain: what a sensor on the housing and a tachometer record.

Bearing forces and the shaft angle (arrays from a simulation) go through a transfer path
(:mod:`.transfer`), an accelerometer and a DAQ (:mod:`.sensor`: anti-alias filter, sampling,
noise, ADC) and a tachometer (:mod:`.tach`); :mod:`.chain` composes them and :mod:`.record`
writes the file a DAQ would (NetCDF, CSV, MATLAB). Nothing here runs the dynamics:
:mod:`geardyn.studies.measure` composes ``simulate()`` and this chain.
"""

from .chain import Measured, MeasurementChain, bearing_forces
from .sensor import G_N, Sensor
from .tach import Tachometer, pulse_times, pulse_train
from .transfer import FRFTable, ModalPath, Mode, mode_accelerance

__all__ = ["MeasurementChain", "Measured", "bearing_forces", "Sensor", "G_N", "Tachometer",
           "pulse_times", "pulse_train", "ModalPath", "Mode", "FRFTable", "mode_accelerance"]
