"""Figures of flexsat: satellite geometry for drawing, modal-analysis plots and animations."""

from flexsat.plots.geometry import (
    HubOutline,
    SatelliteGeometry,
    hub_outline,
    panel_corners_local,
    rot_zyx,
    satellite_geometry,
)
from flexsat.plots.modal import (
    DEFAULT_PEAK_FRACTION,
    animate_mode,
    default_animated_modes,
    mode_amplitude,
    plot_frequencies,
    plot_interaction_map,
    write_modal_figures,
)
from flexsat.plots.openloop import (
    OPENLOOP_FIGURES,
    plot_angular_acceleration,
    plot_angular_momentum,
    plot_attitude,
    plot_energy,
    plot_quaternion,
    plot_root_deformation,
    plot_spectrogram,
    plot_tip_displacement,
    plot_torques,
    write_openloop_figures,
)

__all__ = [
    "DEFAULT_PEAK_FRACTION",
    "OPENLOOP_FIGURES",
    "HubOutline",
    "SatelliteGeometry",
    "animate_mode",
    "default_animated_modes",
    "hub_outline",
    "mode_amplitude",
    "panel_corners_local",
    "plot_angular_acceleration",
    "plot_angular_momentum",
    "plot_attitude",
    "plot_energy",
    "plot_frequencies",
    "plot_interaction_map",
    "plot_quaternion",
    "plot_root_deformation",
    "plot_spectrogram",
    "plot_tip_displacement",
    "plot_torques",
    "rot_zyx",
    "satellite_geometry",
    "write_modal_figures",
    "write_openloop_figures",
]
