//! The hard cases of the suite: which scenes, with which integrators, and how a
//! `--quick` run shortens them. Each case's scene is built into the binary, so
//! the suite runs from any directory.

use crate::math::Scalar;
use crate::scene::Integrator;

const ALL: &[Integrator] = &[
    Integrator::SymplecticEuler,
    Integrator::Rk4,
    Integrator::Implicit,
];

/// One hard case: a scene of `scenes/hard/` and how the suite runs it.
#[derive(Debug, Clone, Copy)]
pub struct Case {
    /// Short name (`--case NAME`); the scene file is `NAME.toml`.
    pub name: &'static str,
    /// The text of `scenes/hard/NAME.toml`, built in (empty for [`OTHER`]).
    pub toml: &'static str,
    /// Other files the scene reads (`cloth.path`), built in: name and text.
    pub files: &'static [(&'static str, &'static str)],
    /// What the case stresses, one line.
    pub stresses: &'static str,
    /// The integrators the case is run with.
    pub integrators: &'static [Integrator],
    /// The integrators of a `--quick` run (a subset of `integrators`).
    pub quick_integrators: &'static [Integrator],
    /// Whether the case is also run with adaptivity off (the scenes all adapt).
    pub adapt_off: bool,
    /// `--quick`: the longest simulated duration, s (the scene's own when shorter).
    pub quick_duration: Scalar,
    /// `--quick`: cloth resolution (`None`: the scene's, e.g. an OBJ mesh).
    pub quick_resolution: Option<u32>,
}

/// The hard-case suite.
pub const CASES: &[Case] = &[
    Case {
        name: "stiff",
        toml: include_str!("../../scenes/hard/stiff.toml"),
        files: &[],
        stresses: "stretch 1e4 N/m, 0.1 kg/m^2; implicit at one step per frame",
        integrators: ALL,
        quick_integrators: ALL,
        adapt_off: true,
        quick_duration: 1.0,
        quick_resolution: Some(8),
    },
    Case {
        name: "impact",
        toml: include_str!("../../scenes/hard/impact.toml"),
        files: &[],
        stresses: "20 m/s impact on a 5 mm box",
        integrators: ALL,
        quick_integrators: ALL,
        adapt_off: true,
        quick_duration: 2.3,
        quick_resolution: Some(8),
    },
    Case {
        name: "wind",
        toml: include_str!("../../scenes/hard/wind.toml"),
        files: &[],
        stresses: "30 m/s wind on a flag for 10 s",
        integrators: ALL,
        quick_integrators: ALL,
        adapt_off: true,
        quick_duration: 1.0,
        quick_resolution: Some(8),
    },
    Case {
        name: "yank",
        toml: include_str!("../../scenes/hard/yank.toml"),
        files: &[],
        stresses: "pinned corner yanked at 50 m/s^2",
        integrators: ALL,
        quick_integrators: ALL,
        adapt_off: true,
        quick_duration: 0.5,
        quick_resolution: Some(8),
    },
    Case {
        name: "sliver",
        toml: include_str!("../../scenes/hard/sliver.toml"),
        files: &[("sliver.obj", include_str!("../../scenes/hard/sliver.obj"))],
        stresses: "input mesh with sliver triangles (aspect 1e-3)",
        integrators: &[Integrator::Implicit],
        quick_integrators: &[Integrator::Implicit],
        adapt_off: true,
        quick_duration: 0.5,
        quick_resolution: None,
    },
    Case {
        name: "long",
        toml: include_str!("../../scenes/hard/long.toml"),
        files: &[],
        stresses: "20 s run",
        integrators: ALL,
        quick_integrators: ALL,
        adapt_off: true,
        quick_duration: 4.0,
        quick_resolution: Some(8),
    },
    Case {
        name: "thrash",
        toml: include_str!("../../scenes/hard/thrash.toml"),
        files: &[],
        stresses: "refine 10 deg / coarsen 9.9 deg, every step, rollback",
        integrators: ALL,
        quick_integrators: ALL,
        adapt_off: false,
        quick_duration: 0.5,
        quick_resolution: Some(8),
    },
    Case {
        name: "crumple",
        toml: include_str!("../../scenes/hard/crumple.toml"),
        files: &[],
        stresses: "crumpling on the floor with self-contact",
        integrators: ALL,
        quick_integrators: &[Integrator::Implicit],
        adapt_off: true,
        quick_duration: 0.6,
        quick_resolution: Some(10),
    },
];

/// How the suite runs a scene of a `--suite` folder that names no hard case:
/// every integrator, adaptivity on (when the scene adapts) and off, and
/// `--quick` cuts it to at most 1 s at its own resolution.
pub const OTHER: Case = Case {
    name: "",
    toml: "",
    files: &[],
    stresses: "a scene of a --suite folder",
    integrators: ALL,
    quick_integrators: ALL,
    adapt_off: true,
    quick_duration: 1.0,
    quick_resolution: None,
};
