"""Figures of runs and studies (figures), their shared style (style) and animations (animate).

The figure functions are importable from here: ``from daeclear.plot import plot_channel``.
"""

from .figures import (
    plot_channel, plot_force_penetration, plot_force_time, save_response_figure, Window, RESPONSE_CHANNELS,
    save_figure, plot_journal_orbit, plot_phase_portrait, plot_step_sizes, plot_cases,
    plot_revolute_response, plot_slider_path, plot_translational_response, MAX_PANELS_PER_ROW,
    CLEARANCE_PANELS, clearance_joints, default_channels, plot_run, save_run_figure, plot_work_precision,
    MOTION_COLORS, plot_poincare_section, plot_bifurcation, plot_motion_map, plot_sensitivity_horizon,
    plot_sensitivities, save_sensitivity_figure)

__all__ = ["plot_channel", "plot_force_penetration", "plot_force_time", "save_response_figure", "Window",
           "RESPONSE_CHANNELS", "save_figure", "plot_journal_orbit", "plot_phase_portrait", "plot_step_sizes",
           "plot_cases", "plot_revolute_response", "plot_slider_path", "plot_translational_response",
           "MAX_PANELS_PER_ROW", "CLEARANCE_PANELS", "clearance_joints", "default_channels", "plot_run",
           "save_run_figure", "plot_work_precision", "MOTION_COLORS", "plot_poincare_section", "plot_bifurcation",
           "plot_motion_map", "plot_sensitivity_horizon", "plot_sensitivities", "save_sensitivity_figure"]
