"""Analysis of trajectories: steady state, event-located peaks, classification, spectra,
intensity (Eq. 16), the relative-motion angle (Fig. 11) and the outcomes' vocabulary."""

from .classify import SIGNALS, Classification, classify, classify_response
from .intensity import angle_range, intensity, relative_motion_angle, trajectory_intensities
from .outcome import OUTCOMES, is_stick_slip, outcome_code, outcome_names
from .peaks import Peaks, find_peaks, hermite_value, trajectory_peaks
from .period import Periodicity, detect_period
from .signal import REST_AMPLITUDE, hermite_crossings, spectral_peak, spectrum, stick_time
from .steady import SteadyState, fundamental_frequency, summarize

__all__ = [
    "SteadyState", "fundamental_frequency", "summarize", "REST_AMPLITUDE", "hermite_crossings", "spectrum",
    "spectral_peak", "stick_time", "Periodicity", "detect_period",
    "Peaks", "find_peaks", "hermite_value", "trajectory_peaks",
    "SIGNALS", "Classification", "classify", "classify_response",
    "OUTCOMES", "outcome_code", "outcome_names", "is_stick_slip",
    "intensity", "trajectory_intensities", "relative_motion_angle", "angle_range",
]
