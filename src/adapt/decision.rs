//! Why the mesh is as it is: the criterion's reading at a triangle (its value
//! against its threshold, as a ratio that refines above 1, and the term that
//! set it), the state that keeps a triangle from doing what the criterion asks,
//! and the reason of every remeshing event. Nothing here decides anything: the
//! passes decide with their own tests (`marks.rs`, `sizing.rs`) and these
//! values report them, for the recording (`docs/recording.md`, "Decisions").

use std::fmt;

use crate::math::{Scalar, Vector};

/// The term of the criterion that a reading comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Term {
    /// The angle criterion: the largest dihedral angle at the triangle's edges
    /// over `refine_angle`.
    #[default]
    Angle,
    /// The sizing criterion's curvature term: the triangle's centroid spacing
    /// over the spacing the curvature asks for (`kappa * D / refine_angle`).
    Curvature,
    /// The sizing criterion's strain term: the largest strain jump at the
    /// triangle's edges over `refine_strain`.
    Strain,
    /// The sizing criterion's obstacle term: the largest lean towards an
    /// obstacle over `refine_obstacle`.
    Obstacle,
}

impl Term {
    /// Every term, in code order ([`Term::code`]).
    pub const ALL: [Term; 4] = [Term::Angle, Term::Curvature, Term::Strain, Term::Obstacle];

    /// The term's name as the recording writes it.
    pub const fn name(self) -> &'static str {
        match self {
            Term::Angle => "angle",
            Term::Curvature => "curvature",
            Term::Strain => "strain",
            Term::Obstacle => "obstacle",
        }
    }

    /// The term's number in the recording (its index in [`Term::ALL`]).
    pub fn code(self) -> u8 {
        self as u8
    }
}

/// What the criterion reads at one node of the mesh.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Reading {
    /// The largest of the criterion's terms against their thresholds: the node
    /// refines above 1.
    pub ratio: Scalar,
    /// The term that gave `ratio`.
    pub term: Term,
    /// The largest dihedral angle at the node's edges, degrees.
    pub angle: Scalar,
}

impl Reading {
    /// The angle criterion's reading of a node whose largest angle is `angle`
    /// degrees, against `refine_angle` degrees.
    pub fn of_angle(angle: Scalar, refine_angle: Scalar) -> Reading {
        Reading {
            ratio: angle / refine_angle,
            term: Term::Angle,
            angle,
        }
    }

    /// The reading of the largest of several terms (each a ratio to its
    /// threshold), the first on a tie; `angle` is the node's largest angle.
    pub fn largest(terms: &[(Term, Scalar)], angle: Scalar) -> Reading {
        let (term, ratio) =
            terms
                .iter()
                .copied()
                .fold((Term::Angle, Scalar::NEG_INFINITY), |best, t| {
                    if t.1 > best.1 { t } else { best }
                });
        Reading {
            ratio: ratio.max(0.0),
            term,
            angle,
        }
    }
}

impl fmt::Display for Reading {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ratio {:.3} (angle {:.2} deg)",
            self.term.name(),
            self.ratio,
            self.angle
        )
    }
}

/// What holds a triangle where it is, against what the criterion asks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TriangleState {
    /// Nothing: it refines when its ratio passes 1 and coarsens when its
    /// parent's reading allows it.
    #[default]
    Free,
    /// Its ratio is past 1 but it is at `max_level`.
    AtMaxLevel,
    /// Its ratio is past 1 but a split would make edges shorter than
    /// `min_edge_length`.
    AtMinEdge,
    /// The criterion would merge it into its parent, but the level rule keeps
    /// it: a neighbour is two splits finer along the parent's edges, or keeps
    /// more than one of their midpoints.
    KeptByLevelRule,
    /// A rollback's refinement made it, and no pass has merged it since.
    HeldByRollback,
}

impl TriangleState {
    /// Every state, in code order ([`TriangleState::code`]).
    pub const ALL: [TriangleState; 5] = [
        TriangleState::Free,
        TriangleState::AtMaxLevel,
        TriangleState::AtMinEdge,
        TriangleState::KeptByLevelRule,
        TriangleState::HeldByRollback,
    ];

    /// The state's name as the recording writes it.
    pub const fn name(self) -> &'static str {
        match self {
            TriangleState::Free => "free",
            TriangleState::AtMaxLevel => "at max_level",
            TriangleState::AtMinEdge => "at min_edge_length",
            TriangleState::KeptByLevelRule => "kept by level rule",
            TriangleState::HeldByRollback => "held by rollback",
        }
    }

    /// The state's number in the recording (its index in [`TriangleState::ALL`]).
    pub fn code(self) -> u8 {
        self as u8
    }
}

/// The criterion's reading and the state of one triangle of the world's mesh.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TriangleDecision {
    /// What the criterion reads at the triangle (at its leaf, for red-green).
    pub reading: Reading,
    /// What holds it.
    pub state: TriangleState,
}

/// Why a merge the criterion asked for was not done.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// A neighbour is two splits finer along the parent's edges: merging would
    /// leave a hanging node at a quarter point.
    NeighbourTwoFiner,
    /// Neighbours that do not merge keep this many of the parent's edge
    /// midpoints (more than one): closure would split it again at once.
    MidpointsInUse(usize),
}

/// Why a remeshing event happened.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reason {
    /// A split or merge the criterion asked for, with its reading (for a
    /// merge: the parent's, with `limit` the ratio it had to stay under).
    Criterion {
        /// The reading.
        reading: Reading,
        /// For a merge, the ratio the merged parent had to stay under
        /// (1 over the hysteresis); 1 for a split.
        limit: Scalar,
    },
    /// A split forced by 1-irregularity: splitting the finer neighbour at
    /// `neighbour` (its centroid, m) would otherwise leave two levels across
    /// an edge.
    Neighbour {
        /// The neighbour's centroid, m.
        neighbour: Vector,
        /// The neighbour's level.
        level: u8,
    },
    /// A split forced by closure: two or more hanging nodes on its edges.
    Closure,
    /// A split by the criterion of a parent that the previous pass merged.
    Bounce {
        /// The criterion's reading at the split.
        reading: Reading,
        /// How many times the parent's merges have bounced, this one included
        /// (its hysteresis is doubled that many times).
        bounces: u32,
    },
    /// A merge the criterion asked for that the level rule refused.
    Refused(Refusal),
    /// A rollback: the step bent the mesh past the criterion.
    Rollback {
        /// The largest reading among the leaves marked.
        reading: Reading,
        /// Leaves marked for refinement.
        marked: usize,
    },
    /// A split of a rollback's refinement, with the angle that asked.
    RollbackSplit {
        /// The angle at the leaf, degrees.
        angle: Scalar,
    },
    /// An operation given directly (tests, tools), with the angle given.
    Given {
        /// The angle given with it, degrees, if any.
        angle: Option<Scalar>,
    },
    /// An edge flip of the edge method: the mesh's quality.
    Quality,
    /// An edge collapse (edge method) or a grid line removed (tensor method):
    /// every angle around is below the coarsening limit.
    Flat,
}

impl fmt::Display for Reason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Reason::Criterion { reading, limit } if limit < 1.0 => {
                write!(f, "criterion: {reading} <= limit {limit:.3}")
            }
            Reason::Criterion { reading, .. } => write!(f, "criterion: {reading} > 1"),
            Reason::Neighbour { neighbour, level } => write!(
                f,
                "forced by level rule: neighbour at level {level} at ({:.3}, {:.3}, {:.3}) m split",
                neighbour.x, neighbour.y, neighbour.z
            ),
            Reason::Closure => write!(f, "forced by closure: two or more hanging nodes"),
            Reason::Bounce { reading, bounces } => write!(
                f,
                "bounced: the previous pass merged it, criterion: {reading} > 1; \
                 bounce {bounces}, hysteresis doubled {bounces} times"
            ),
            Reason::Refused(Refusal::NeighbourTwoFiner) => write!(
                f,
                "refused by level rule: a neighbour is two splits finer along its edges"
            ),
            Reason::Refused(Refusal::MidpointsInUse(n)) => write!(
                f,
                "refused by level rule: neighbours keep {n} of its edge midpoints"
            ),
            Reason::Rollback { reading, marked } => write!(
                f,
                "the step bent it past the criterion: {reading}; {marked} leaves marked"
            ),
            Reason::RollbackSplit { angle } => {
                write!(f, "rollback refinement: angle {angle:.2} deg")
            }
            Reason::Given { angle: Some(a) } => write!(f, "given, angle {a:.2} deg"),
            Reason::Given { angle: None } => write!(f, "given"),
            Reason::Quality => write!(f, "mesh quality"),
            Reason::Flat => write!(f, "flat: every angle around below the coarsening limit"),
        }
    }
}
