//! Pinned vertices: selected by named region in material space (so a selection
//! means the same cloth points on any mesh) and moved by a script, or carried
//! by an obstacle or a part of one (`attach`, `crate::kinematics::carrier`).

mod coverage;

pub use coverage::{PinMismatch, mismatches};

use crate::kinematics::carrier::{AttachError, Carrier};
use crate::kinematics::motion::Track;
use crate::math::{Matrix3, Scalar, Vector, Vector2};
use crate::mesh::{GridCuts, Mesh};
use crate::spec::{ObstacleSpec, Pin, PinMotion};

/// The edges of the `box` regions of `pins`: the lines a generated grid needs
/// so that each box holds exactly the cloth inside it. Other regions (and
/// boxes missing a corner, which [`Pins::select`] refuses) add none.
pub fn box_cuts(pins: &[Pin]) -> GridCuts {
    let mut cuts = GridCuts::default();
    for pin in pins.iter().filter(|p| p.region == "box") {
        if let (Some(a), Some(b)) = (pin.box_min, pin.box_max) {
            cuts.u.extend([a[0], b[0]]);
            cuts.v.extend([a[1], b[1]]);
        }
    }
    cuts
}

/// Why a pin could not be set up.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PinError {
    /// The region string is not understood.
    #[error(
        "pin {pin}: unknown region `{region}`; allowed: corner:top_left|top_right|bottom_left|bottom_right, edge:top|bottom|left|right, box, disk, all"
    )]
    UnknownRegion {
        /// Pin index.
        pin: usize,
        /// The region string.
        region: String,
    },
    /// A `box` region without both corners.
    #[error("pin {pin}: region `box` needs box_min and box_max")]
    MissingBox {
        /// Pin index.
        pin: usize,
    },
    /// A `disk` region without its radius.
    #[error("pin {pin}: region `disk` needs disk_radius")]
    MissingRadius {
        /// Pin index.
        pin: usize,
    },
    /// `attach` names nothing that can carry pins (validation normally
    /// catches this first, with the line).
    #[error("pin {pin}: attach: {source}")]
    Attach {
        /// Pin index.
        pin: usize,
        /// What is wrong.
        source: AttachError,
    },
    /// The region contains no vertex of the mesh.
    #[error("pin {pin}: region `{region}` contains no vertex of the cloth")]
    Empty {
        /// Pin index.
        pin: usize,
        /// The region string.
        region: String,
    },
}

/// How the vertices of one `[[pin]]` move.
#[derive(Debug, Clone, PartialEq)]
pub enum PinPath {
    /// Held in place.
    Fixed,
    /// `x(t) = x0 + velocity t + acceleration t^2 / 2`.
    Linear {
        /// m/s.
        velocity: Vector,
        /// m/s^2.
        acceleration: Vector,
    },
    /// Turned about `axis` through `center` at `angular_velocity`.
    Circular {
        /// A point on the rotation axis, m.
        center: Vector,
        /// Unit rotation axis.
        axis: Vector,
        /// rad/s, right-handed about `axis`.
        angular_velocity: Scalar,
    },
    /// Moved by the keys' translations and turned by their rotations about
    /// `center` (which moves with the translation).
    Keyframed {
        /// The point the rotations turn about at t = 0, m.
        center: Vector,
        /// The keys (validated: at least two).
        track: Track,
    },
    /// Carried by an obstacle or a part of one (`attach`).
    Attached(Carrier),
}

/// The motion script of one `[[pin]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct PinScript {
    /// How the held vertices move.
    pub path: PinPath,
    /// Time at which the pin lets go, s.
    pub release_time: Option<Scalar>,
}

impl PinScript {
    /// The script of `pin`, whose `attach` (if any) names one of `obstacles`.
    fn new(p: usize, pin: &Pin, obstacles: &[ObstacleSpec]) -> Result<PinScript, PinError> {
        let v = Vector::from_array;
        let path = match (&pin.attach, pin.motion) {
            (Some(attach), _) => PinPath::Attached(
                Carrier::new(obstacles, attach)
                    .map_err(|source| PinError::Attach { pin: p, source })?,
            ),
            (None, PinMotion::Fixed) => PinPath::Fixed,
            (None, PinMotion::Linear) => PinPath::Linear {
                velocity: v(pin.velocity),
                acceleration: v(pin.acceleration),
            },
            (None, PinMotion::Circular) => PinPath::Circular {
                center: v(pin.center),
                axis: v(pin.axis).normalize_or_zero(),
                angular_velocity: pin.angular_velocity,
            },
            (None, PinMotion::Keyframed) => PinPath::Keyframed {
                center: v(pin.center),
                track: Track::new(&pin.keyframes, pin.easing, pin.after_last),
            },
        };
        Ok(PinScript {
            path,
            release_time: pin.release_time,
        })
    }

    /// Position and velocity at time `t` of a point that was at `start` at t = 0.
    pub fn at(&self, start: Vector, t: Scalar) -> (Vector, Vector) {
        match &self.path {
            PinPath::Fixed => (start, Vector::ZERO),
            PinPath::Linear {
                velocity,
                acceleration,
            } => (
                start + *velocity * t + *acceleration * (0.5 * t * t),
                *velocity + *acceleration * t,
            ),
            &PinPath::Circular {
                center,
                axis,
                angular_velocity,
            } => {
                let r = Matrix3::from_axis_angle(axis, angular_velocity * t);
                let p = center + r * (start - center);
                (p, (axis * angular_velocity).cross(p - center))
            }
            PinPath::Keyframed { center, track } => {
                let s = track.state(t);
                let centre = *center + s.shift;
                let p = centre + s.rotation * (start - *center);
                (p, s.velocity + s.omega.cross(p - centre))
            }
            PinPath::Attached(carrier) => carrier.follow(start, t),
        }
    }

    /// True when the held vertices move at some time.
    pub fn moves(&self) -> bool {
        match &self.path {
            PinPath::Fixed => false,
            PinPath::Attached(carrier) => carrier.is_moving(),
            _ => true,
        }
    }

    /// True while the pin holds (before its release time).
    pub fn holds_at(&self, t: Scalar) -> bool {
        self.release_time.is_none_or(|r| t < r)
    }
}

/// One pinned vertex: which script moves it and where it started.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    /// The vertex.
    pub vertex: u32,
    /// Index into [`Pins::scripts`].
    pub pin: u32,
    /// World position at t = 0.
    pub start: Vector,
}

/// All pins of a world.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Pins {
    /// One script per `[[pin]]` section.
    pub scripts: Vec<PinScript>,
    /// Pinned vertices, sorted by vertex; a vertex in several regions follows the first pin.
    pub anchors: Vec<Anchor>,
}

impl Pins {
    /// Selects each pin's vertices on `mesh` (world positions `x` at t = 0),
    /// for a scene without obstacles (a pin with `attach` is refused).
    pub fn select(pins: &[Pin], mesh: &Mesh, x: &[Vector]) -> Result<Pins, PinError> {
        Pins::select_among(pins, &[], mesh, x)
    }

    /// Selects each pin's vertices on `mesh` (world positions `x` at t = 0);
    /// a pin's `attach` names one of `obstacles`.
    pub fn select_among(
        pins: &[Pin],
        obstacles: &[ObstacleSpec],
        mesh: &Mesh,
        x: &[Vector],
    ) -> Result<Pins, PinError> {
        let (lo, hi) = mesh.material_bounds();
        let tol = 1e-9 * (hi - lo).max_element().max(Scalar::MIN_POSITIVE);
        let mut owner: Vec<Option<u32>> = vec![None; mesh.vertex_count()];
        let mut scripts = Vec::with_capacity(pins.len());
        for (p, pin) in pins.iter().enumerate() {
            let region = Region::parse(p, pin)?;
            let inside = |i: usize| region.contains(mesh.material[i], lo, hi, tol);
            let chosen: Vec<usize> = match region {
                Region::Corner(c) => nearest(&mesh.material, c(lo, hi)).into_iter().collect(),
                _ => (0..mesh.vertex_count()).filter(|&i| inside(i)).collect(),
            };
            if chosen.is_empty() {
                return Err(PinError::Empty {
                    pin: p,
                    region: pin.region.clone(),
                });
            }
            for i in chosen {
                owner[i].get_or_insert(p as u32);
            }
            scripts.push(PinScript::new(p, pin, obstacles)?);
        }
        let anchors = owner
            .iter()
            .enumerate()
            .filter_map(|(i, o)| {
                o.map(|pin| Anchor {
                    vertex: i as u32,
                    pin,
                    start: x[i],
                })
            })
            .collect();
        Ok(Pins { scripts, anchors })
    }

    /// Per vertex: the pin that holds it for good (never lets go), or
    /// `u32::MAX`. Vertices of one such pin move rigidly for the whole run.
    pub fn clamped(&self, vertices: usize) -> Vec<u32> {
        let mut out = vec![u32::MAX; vertices];
        for a in &self.anchors {
            if self.scripts[a.pin as usize].release_time.is_none() {
                out[a.vertex as usize] = a.pin;
            }
        }
        out
    }

    /// Marks in `held` (one flag per vertex) the vertices pinned at time `t`.
    pub fn held_at(&self, t: Scalar, held: &mut [bool]) {
        held.fill(false);
        for a in &self.anchors {
            if self.scripts[a.pin as usize].holds_at(t) {
                held[a.vertex as usize] = true;
            }
        }
    }

    /// Position and velocity of a pinned vertex at time `t`.
    pub fn target(&self, a: &Anchor, t: Scalar) -> (Vector, Vector) {
        self.scripts[a.pin as usize].at(a.start, t)
    }

    /// Moves every holding pin's vertices to their scripted state at time `t`.
    pub fn apply(&self, t: Scalar, x: &mut [Vector], v: &mut [Vector]) {
        for a in &self.anchors {
            if self.scripts[a.pin as usize].holds_at(t) {
                let (p, vel) = self.target(a, t);
                x[a.vertex as usize] = p;
                v[a.vertex as usize] = vel;
            }
        }
    }
}

/// A corner picker maps the material bounds to the corner point.
type CornerFn = fn(Vector2, Vector2) -> Vector2;

/// A pin region in material space.
enum Region {
    /// The vertex nearest to a corner of the material bounds.
    Corner(CornerFn),
    /// The vertices on one side of the material bounds: 0 left, 1 right, 2 bottom, 3 top.
    Side(u8),
    /// The vertices inside a material-space box (inclusive).
    Box(Vector2, Vector2),
    /// The vertices inside a material-space disk, centre and radius (inclusive).
    Disk(Vector2, Scalar),
    /// Every vertex.
    All,
}

impl Region {
    fn parse(p: usize, pin: &Pin) -> Result<Region, PinError> {
        Ok(match pin.region.as_str() {
            "corner:top_left" => Region::Corner(|lo, hi| Vector2::new(lo.x, hi.y)),
            "corner:top_right" => Region::Corner(|_, hi| hi),
            "corner:bottom_left" => Region::Corner(|lo, _| lo),
            "corner:bottom_right" => Region::Corner(|lo, hi| Vector2::new(hi.x, lo.y)),
            "edge:left" => Region::Side(0),
            "edge:right" => Region::Side(1),
            "edge:bottom" => Region::Side(2),
            "edge:top" => Region::Side(3),
            "all" => Region::All,
            "box" => match (pin.box_min, pin.box_max) {
                (Some(a), Some(b)) => Region::Box(Vector2::from_array(a), Vector2::from_array(b)),
                _ => return Err(PinError::MissingBox { pin: p }),
            },
            "disk" => match pin.disk_radius {
                Some(r) => {
                    Region::Disk(Vector2::from_array(pin.disk_center.unwrap_or([0.0; 2])), r)
                }
                None => return Err(PinError::MissingRadius { pin: p }),
            },
            _ => {
                return Err(PinError::UnknownRegion {
                    pin: p,
                    region: pin.region.clone(),
                });
            }
        })
    }

    /// True when material point `m` lies in the region (bounds `lo`, `hi`, tolerance `tol`).
    fn contains(&self, m: Vector2, lo: Vector2, hi: Vector2, tol: Scalar) -> bool {
        match *self {
            Region::Corner(c) => m.distance(c(lo, hi)) <= tol,
            Region::Side(0) => m.x <= lo.x + tol,
            Region::Side(1) => m.x >= hi.x - tol,
            Region::Side(2) => m.y <= lo.y + tol,
            Region::Side(_) => m.y >= hi.y - tol,
            Region::Box(a, b) => m.cmpge(a - tol).all() && m.cmple(b + tol).all(),
            Region::Disk(c, r) => m.distance(c) <= r + tol,
            Region::All => true,
        }
    }
}

/// Index of the vertex nearest to `target` in material space.
fn nearest(material: &[Vector2], target: Vector2) -> Option<usize> {
    (0..material.len()).min_by(|&a, &b| {
        material[a]
            .distance_squared(target)
            .total_cmp(&material[b].distance_squared(target))
    })
}
