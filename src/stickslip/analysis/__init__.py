"""Analysis of trajectories: steady state, event-located peaks, classification, spectra,
intensity (Eq. 16), the relative-motion angle (Fig. 11) and the outcomes' vocabulary."""

from .. import _startup

#: Public name → the module that defines it, imported on first use (:func:`stickslip._startup.export_on_first_use`).
_EXPORTS = {
    **dict.fromkeys(["SIGNALS", "Classification", "classify", "classify_response"], ".classify"),
    **dict.fromkeys(["angle_range", "intensity", "relative_motion_angle", "trajectory_intensities"], ".intensity"),
    **dict.fromkeys(["OUTCOMES", "is_stick_slip", "outcome_code", "outcome_names"], ".outcome"),
    **dict.fromkeys(["Peaks", "find_peaks", "hermite_value", "trajectory_peaks"], ".peaks"),
    **dict.fromkeys(["Periodicity", "detect_period"], ".period"),
    **dict.fromkeys(["REST_AMPLITUDE", "hermite_crossings", "spectral_peak", "spectrum", "stick_time"], ".signal"),
    **dict.fromkeys(["SteadyState", "fundamental_frequency", "summarize"], ".steady"),
}

__all__ = [
    "SteadyState", "fundamental_frequency", "summarize", "REST_AMPLITUDE", "hermite_crossings", "spectrum",
    "spectral_peak", "stick_time", "Periodicity", "detect_period",
    "Peaks", "find_peaks", "hermite_value", "trajectory_peaks",
    "SIGNALS", "Classification", "classify", "classify_response",
    "OUTCOMES", "outcome_code", "outcome_names", "is_stick_slip",
    "intensity", "trajectory_intensities", "relative_motion_angle", "angle_range",
]

_startup.export_on_first_use(__name__, _EXPORTS)
