//! Running a scene: build the world, step it frame by frame, record every frame,
//! and summarise. The step is a short list of named phases:
//! forces + integrate (the stepper), health check, record.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

mod recording;

use crate::adapt::{AdaptConfig, AdaptStats, Adapter, edge_angles};
use crate::collide::{CollideError, Collider, CollisionStats, StepCloth};
use crate::math::{Scalar, Vector, deterministic_sum};
use crate::physics::{Energy, Model, Stepper};
use crate::record::{
    EdgeDisplay, LiveViewer, RecordError, RecordTarget, Recorder, obj::write_frame_obj,
};
use crate::scene::{Scene, TimeStep};
use crate::summary::{EnergySummary, Range, RecordingSummary, Summary};
use crate::world::{BuildError, World};

/// How often a failing frame is retried with half the step before giving up.
pub const MAX_STEP_HALVINGS: u32 = 4;

/// A frame whose energy minus external work rose by more than this share of the
/// run's energy scale ([`EnergyBound`]) is retried with halved steps: large steps
/// through an impact (one vertex stopped, its neighbours still moving) stretch the
/// springs and create energy that smaller steps do not (a tablecloth at 4 ms steps
/// gained 1.48 J, at 1 ms none).
pub const ENERGY_GAIN_TOLERANCE: Scalar = 0.01;

/// The most halvings spent on an energy gain (the frame is then accepted).
pub const MAX_ENERGY_HALVINGS: u32 = 3;

/// A step "explodes" when the cloth's kinetic plus gravitational energy exceeds the
/// physical bound (initial energy plus the work of wind, pins and moving obstacles)
/// by this many times the run's energy scale ([`EnergyBound`]): far beyond any
/// discretisation error, only an instability gets there.
pub const EXPLOSION_FACTOR: Scalar = 1.0;

/// Why a step was rejected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepFailure {
    /// A position became NaN or infinite.
    NonFinite,
    /// The energy exceeded its bound by [`EXPLOSION_FACTOR`] energy scales.
    Explosion {
        /// Kinetic plus gravitational energy after the step, J.
        energy: Scalar,
        /// The bound it exceeded, J.
        bound: Scalar,
    },
}

impl std::fmt::Display for StepFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepFailure::NonFinite => write!(f, "positions became NaN or infinite"),
            StepFailure::Explosion { energy, bound } => write!(
                f,
                "the energy exploded (kinetic + gravitational {energy:.4e} J, above the explosion limit {bound:.4e} J)"
            ),
        }
    }
}

/// What to produce besides the simulation itself.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Write the recording here (`None`: no recording).
    pub record: Option<PathBuf>,
    /// Write each recorded frame as an OBJ into this directory.
    pub obj_dir: Option<PathBuf>,
    /// Worker threads (`None`: rayon's default, one per core).
    pub threads: Option<usize>,
    /// Also stream the recording to a live viewer (with or without a file).
    pub live: Option<LiveViewer>,
    /// Record (and export OBJ for) every K-th frame only; 0 and 1 both mean every frame.
    /// Frame 0 and the last frame are always recorded, and so is the last good frame of a run
    /// stopped early; events of the frames left out go with the next recorded frame.
    pub record_every: u64,
    /// Which edges `cloth/edges` shows.
    pub edges: EdgeDisplay,
}

/// Progress report after each frame.
#[derive(Debug, Clone, Copy)]
pub struct Progress {
    /// Frames done (including the initial frame).
    pub frame: u64,
    /// Frames in the whole run.
    pub frames: u64,
    /// Simulated time, s.
    pub sim_time: Scalar,
}

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The scene could not become a world.
    #[error("{0}")]
    Build(#[from] BuildError),
    /// Recording failed.
    #[error("recording: {0}")]
    Record(#[from] RecordError),
    /// The scene's obstacles could not be built.
    #[error("{0}")]
    Collide(#[from] CollideError),
    /// Remeshing produced an invalid mesh (a bug: please report it).
    #[error("adaptive remeshing: {0}")]
    Remesh(#[from] crate::mesh::MeshError),
    /// Internal: every step size tried in a frame failed (becomes `Numerical`).
    #[error("all step sizes failed, down to {last_dt:.3e} s: {failure}")]
    StepFailed {
        /// The last step tried.
        last_dt: Scalar,
        /// What went wrong with it.
        failure: StepFailure,
        /// The step (counted from the start of the run) that failed.
        step: u64,
    },
    /// The thread pool could not be created.
    #[error("cannot start {threads} worker threads: {reason}")]
    Threads {
        /// Requested threads.
        threads: usize,
        /// Why.
        reason: String,
    },
    /// The state became non-finite even with the smallest step tried.
    #[error(
        "numerical failure at step {step} in frame {frame} (t = {time:.4} s): {failure} even with the step halved {halvings} times to {dt:.3e} s; the run stopped and the recording holds every frame up to the last good one. Likely cause: the time step is too large for the stiffness ({cause})"
    )]
    Numerical {
        /// The step (counted from the start of the run) that failed.
        step: u64,
        /// What went wrong.
        failure: StepFailure,
        /// Frame whose steps failed.
        frame: u64,
        /// Simulated time at the start of that frame.
        time: Scalar,
        /// Halvings tried.
        halvings: u32,
        /// The last step size tried.
        dt: Scalar,
        /// A hint naming the likely cause.
        cause: String,
        /// What the run produced up to the failure.
        summary: Box<Summary>,
    },
}

/// The cloth's state at a frame, handed to the observer of [`run_observed`]
/// (the benchmark samples its error metric from it).
#[derive(Debug, Clone, Copy)]
pub struct FrameState<'a> {
    /// Frame index (0 is the initial state).
    pub frame: u64,
    /// Simulated time, s.
    pub sim_time: Scalar,
    /// World positions, m.
    pub positions: &'a [Vector],
    /// Material (rest) coordinates of the same vertices, m.
    pub material: &'a [crate::math::Vector2],
    /// Triangles (vertex indices).
    pub triangles: &'a [[u32; 3]],
}

/// Runs `scene` to the end (or until `interrupt` is set), calling `progress`
/// after every frame.
pub fn run(
    scene: &Scene,
    opts: &RunOptions,
    interrupt: &AtomicBool,
    progress: &mut (dyn FnMut(Progress) + Send),
) -> Result<Summary, RunError> {
    run_observed(scene, opts, interrupt, progress, &mut |_| {})
}

/// [`run`], also handing every frame's state (after the step, before it is
/// recorded) to `observe`.
pub fn run_observed(
    scene: &Scene,
    opts: &RunOptions,
    interrupt: &AtomicBool,
    progress: &mut (dyn FnMut(Progress) + Send),
    observe: &mut (dyn FnMut(&FrameState) + Send),
) -> Result<Summary, RunError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| RunError::Threads {
            threads: opts.threads.unwrap_or(0),
            reason: e.to_string(),
        })?;
    pool.install(|| run_in_pool(scene, opts, interrupt, progress, observe))
}

fn run_in_pool(
    scene: &Scene,
    opts: &RunOptions,
    interrupt: &AtomicBool,
    progress: &mut (dyn FnMut(Progress) + Send),
    observe: &mut (dyn FnMut(&FrameState) + Send),
) -> Result<Summary, RunError> {
    // Open the output first: an unwritable path fails before any simulation.
    let mut recorder = match (&opts.record, &opts.live) {
        (None, None) => None,
        (file, live) => {
            let target = RecordTarget {
                file: file.clone(),
                live: live.clone(),
            };
            Some(Recorder::open(&target, &scene.name, opts.edges)?)
        }
    };
    let every = opts.record_every.max(1);
    if let Some(dir) = &opts.obj_dir {
        std::fs::create_dir_all(dir).map_err(|source| RecordError::Obj {
            path: dir.clone(),
            source,
        })?;
    }
    let mut world = World::from_scene(scene)?;
    let model = Model::from_scene(scene);
    let mut stepper = Stepper::new(model, &world);
    stepper.multirate = scene.adapt.as_ref().is_some_and(|a| a.multirate);
    let adapter = AdaptConfig::from_scene(scene.adapt.as_ref())
        .map(|c| Adapter::new(c, &world, scene.material.density));
    let collider = Collider::from_scene(scene)?;
    let mut pipe = Pipeline {
        stepper,
        adapter,
        steps_done: 0,
        collider,
        collision: CollisionStats::default(),
        fixed_dt: match scene.simulation.dt {
            TimeStep::Fixed(dt) => Some(dt),
            TimeStep::Auto => None,
        },
        auto_dt: None,
        min_dt: Scalar::INFINITY,
        external_work: 0.0,
        air_power: None,
        bound: EnergyBound {
            initial: 0.0,
            scale: 0.0,
        },
        failure: StepFailure::NonFinite,
        excess_max: 0.0,
        energy_retries: 0,
    };
    pipe.bound = EnergyBound::new(&world, &pipe.stepper);
    let frame_interval = 1.0 / scene.simulation.frame_rate;
    let frames = (scene.simulation.duration * scene.simulation.frame_rate)
        .round()
        .max(1.0) as u64;

    let mut tally = Tally::new(&world, &pipe.stepper);
    let started = Instant::now();
    let mut sim_seconds = 0.0;
    let mut record_seconds = 0.0;
    let mut nan_recoveries = 0u64;
    let mut frames_done = 0u64;
    let mut interrupted = false;
    let mut normals = Vec::new();
    let mut failure = None;
    // Wall time of the last frame's stepping and of the last recorded frame's recording.
    let mut timing = recording::FrameTiming::default();
    let mut recorded_frames = 0u64;
    let mut last_recorded = None;
    for frame in 0..=frames {
        if frame > 0 {
            if interrupt.load(Ordering::Relaxed) {
                interrupted = true;
                break;
            }
            let t0 = Instant::now();
            match pipe.advance_frame(&mut world, frame_interval) {
                Ok(recoveries) => nan_recoveries += recoveries,
                Err(RunError::StepFailed {
                    last_dt,
                    failure: what,
                    step,
                }) => {
                    failure = Some((frame, last_dt, what, step));
                    break;
                }
                Err(e) => return Err(e),
            }
            timing.sim_s = t0.elapsed().as_secs_f64();
            sim_seconds += timing.sim_s;
        }
        let energy = pipe.stepper.energy(&world);
        tally.observe(&world, energy);
        observe(&FrameState {
            frame,
            sim_time: world.time,
            positions: &world.x,
            material: &world.mesh.material,
            triangles: &world.mesh.triangles,
        });
        let t1 = Instant::now();
        let record_now = frame % every == 0 || frame == frames;
        if record_now {
            if let Some(rec) = recorder.as_mut() {
                let view = recording::Snapshot {
                    frame,
                    energy,
                    timing,
                };
                recording::record_state(rec, &world, &mut pipe, &view, &mut normals)?;
                recorded_frames += 1;
                last_recorded = Some(frame);
            }
            if let Some(dir) = &opts.obj_dir {
                write_frame_obj(
                    dir,
                    frame,
                    &world.x,
                    &world.mesh.material,
                    &world.mesh.triangles,
                )?;
            }
            timing.record_s = t1.elapsed().as_secs_f64();
            record_seconds += timing.record_s;
        }
        if recorder.is_none() {
            // Nobody takes the events: drop them rather than let them pile up.
            pipe.adapter.as_mut().map(Adapter::take_events);
        }
        frames_done = frame + 1;
        progress(Progress {
            frame: frames_done,
            frames: frames + 1,
            sim_time: world.time,
        });
    }
    // A run stopped early (Ctrl-C, numerical failure) after frames left out by
    // `record_every`: record the last good state too, with the pending events.
    if let Some(rec) = recorder.as_mut()
        && let Some(last) = frames_done.checked_sub(1)
        && last_recorded != Some(last)
    {
        let t1 = Instant::now();
        let energy = pipe.stepper.energy(&world);
        let view = recording::Snapshot {
            frame: last,
            energy,
            timing,
        };
        recording::record_state(rec, &world, &mut pipe, &view, &mut normals)?;
        recorded_frames += 1;
        record_seconds += t1.elapsed().as_secs_f64();
    }
    let recording = match recorder {
        Some(rec) => {
            let bytes = rec.finish()?;
            opts.record
                .clone()
                .map(|path| (path, bytes, recorded_frames))
        }
        None => None,
    };
    let summary = tally.finish(TallyEnd {
        scene: scene.name.clone(),
        frames: frames_done,
        steps: pipe.stepper.stats.steps,
        sim_time: world.time,
        wall_time_s: started.elapsed().as_secs_f64(),
        sim_wall_s: sim_seconds,
        record_wall_s: record_seconds,
        dt: if pipe.min_dt.is_finite() {
            pipe.min_dt
        } else {
            pipe.step_size(&world)
        },
        nan_recoveries,
        interrupted,
        recording,
        stepper: &pipe.stepper,
        adapt: pipe.adapter.as_ref().map(|a| a.stats),
        collision: pipe.collision,
        cusick: pipe.collider.as_ref().and_then(|c| c.cusick(scene, &world)),
        external_work: pipe.work(),
        excess_max: pipe.excess_max,
        energy_retries: pipe.energy_retries,
    });
    match failure {
        None => Ok(summary),
        Some((frame, last_dt, what, step)) => Err(RunError::Numerical {
            step,
            failure: what,
            frame,
            time: world.time,
            halvings: MAX_STEP_HALVINGS,
            dt: last_dt,
            cause: format!(
                "step {:.3e} s with the {:?} integrator; try a smaller `simulation.dt`, `dt = \"auto\"`, or `integrator = \"implicit\"`",
                pipe.step_size(&world),
                pipe.stepper.model.integrator
            ),
            summary: Box::new(summary),
        }),
    }
}

/// The per-run machinery that advances the world: the stepper (forces and
/// integration), the adapter (remeshing), and the global step counter.
struct Pipeline {
    stepper: Stepper,
    adapter: Option<Adapter>,
    /// Steps completed (not counting retried ones).
    steps_done: u64,
    /// Obstacle and self-collision passes (`None`: the scene has neither).
    collider: Option<Collider>,
    /// What the collision passes did.
    collision: CollisionStats,
    /// The user's fixed step, or `None` for `dt = "auto"`.
    fixed_dt: Option<Scalar>,
    /// The automatic step for the current mesh (recomputed after remeshing,
    /// since refinement lowers the explicit stability limit).
    auto_dt: Option<Scalar>,
    /// Smallest step taken so far.
    min_dt: Scalar,
    /// Work done on the cloth by wind, moving air and moving pins so far, J
    /// (moving obstacles' is in `collision`).
    external_work: Scalar,
    /// Power of the air at the end of the last step, W (`None`: not known).
    air_power: Option<Scalar>,
    /// The energy bound the explosion check holds the cloth to.
    bound: EnergyBound,
    /// Why the last rejected step failed.
    failure: StepFailure,
    /// Largest `E(t) - E(0) - W(t)` at the end of a frame so far, J.
    excess_max: Scalar,
    /// Frames retried because their energy rose ([`ENERGY_GAIN_TOLERANCE`]).
    energy_retries: u64,
}

/// The energy the cloth may have: its initial total plus the external work, and the
/// scale against which an excess counts as an explosion.
#[derive(Debug, Clone, Copy)]
struct EnergyBound {
    /// Total energy at the start, J.
    initial: Scalar,
    /// `|E0| + KE0 + m |g| D` (D: the cloth's diagonal), J: the energies the run
    /// naturally trades (a fall through the cloth's own size).
    scale: Scalar,
}

impl EnergyBound {
    fn new(world: &World, stepper: &Stepper) -> EnergyBound {
        let e = stepper.energy(world);
        let mass = stepper.elements.total_mass();
        let g = stepper
            .model
            .external
            .gravity
            .unwrap_or(Vector::ZERO)
            .length();
        let (lo, hi) = world
            .x
            .iter()
            .fold((Vector::INFINITY, Vector::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        let diagonal = (hi - lo).length();
        EnergyBound {
            initial: e.total(),
            scale: e.total().abs() + e.kinetic + mass * g * diagonal.max(0.0),
        }
    }
}

impl Pipeline {
    /// Advances one frame; on a non-finite state or an energy explosion, restores
    /// the frame's start (mesh included) and retries with the step halved (up to
    /// [`MAX_STEP_HALVINGS`] times). A frame whose energy rose above its bound by
    /// more than [`ENERGY_GAIN_TOLERANCE`] energy scales is retried the same way, up
    /// to [`MAX_ENERGY_HALVINGS`] times and only while halving helps (the gain at
    /// least halves), then accepted. Returns the number of retries, or the last
    /// step tried when all failed.
    fn advance_frame(
        &mut self,
        world: &mut World,
        frame_interval: Scalar,
    ) -> Result<u64, RunError> {
        let start = world.clone();
        let adapter_start = self.adapter.clone();
        let steps_start = self.steps_done;
        let (work_start, collision_start) = (self.external_work, self.collision);
        let t0 = world.time;
        // E - W at the frame start: without numerical error it can only fall.
        let balance_start = self.stepper.energy(world).total() - self.work();
        let mut last_gain = Scalar::INFINITY;
        for halving in 0..=MAX_STEP_HALVINGS {
            let shrink = (1u64 << halving) as Scalar;
            let mut healthy = true;
            let mut done = 0.0;
            // Steps of the current mesh's size, the last ones evened out so the
            // frame ends exactly on its time.
            while done < frame_interval * (1.0 - 1e-12) {
                let remaining = frame_interval - done;
                let target = self.step_size(world) / shrink;
                let h = remaining / (remaining / target * (1.0 - 1e-12)).ceil().max(1.0);
                if !self.step(world, h)? {
                    healthy = false;
                    break;
                }
                self.min_dt = self.min_dt.min(h);
                done += h;
            }
            world.time = t0 + frame_interval;
            if healthy {
                let balance = self.stepper.energy(world).total() - self.work();
                let gain = balance - balance_start;
                let retry = gain > ENERGY_GAIN_TOLERANCE * self.bound.scale
                    && halving < MAX_ENERGY_HALVINGS
                    && gain < 0.75 * last_gain;
                if !retry {
                    self.excess_max = self.excess_max.max(balance - self.bound.initial);
                    return Ok(halving as u64);
                }
                last_gain = gain;
                self.energy_retries += 1;
            }
            *world = start.clone();
            self.adapter = adapter_start.clone();
            self.steps_done = steps_start;
            (self.external_work, self.collision) = (work_start, collision_start);
            self.mesh_changed(world);
        }
        let last_dt = self.step_size(world) / (1u64 << MAX_STEP_HALVINGS) as Scalar;
        Err(RunError::StepFailed {
            last_dt,
            failure: self.failure,
            step: self.steps_done + 1,
        })
    }

    /// The step for the current mesh: the fixed one, or the automatic estimate.
    fn step_size(&mut self, world: &World) -> Scalar {
        if let Some(dt) = self.fixed_dt {
            return dt;
        }
        *self
            .auto_dt
            .get_or_insert_with(|| self.stepper.auto_dt(world))
    }

    /// One step, in phases: integrate (forces and integrator), health check,
    /// rollback (paper A: redo the step on a refined mesh when it bent past the
    /// upper threshold), adapt. Returns false when the state became non-finite.
    fn step(&mut self, world: &mut World, h: Scalar) -> Result<bool, RunError> {
        let rollback = self.adapter.as_ref().is_some_and(|a| a.config.rollback);
        let mut tries = 0;
        loop {
            let before = rollback.then(|| (world.x.clone(), world.v.clone(), world.time));
            if !self.integrate(world, h) {
                return Ok(false);
            }
            if let (Some(ad), Some((x, v, t))) = (self.adapter.as_mut(), before)
                && tries < ad.config.max_rollbacks
            {
                let marks = ad.refinement_marks(world, &edge_angles(world));
                if !marks.is_empty() {
                    (world.x, world.v, world.time) = (x, v, t);
                    ad.note_rollback(world, self.steps_done);
                    ad.refine(world, &marks, self.steps_done)?;
                    self.mesh_changed(world);
                    tries += 1;
                    continue;
                }
            }
            break;
        }
        self.steps_done += 1;
        if let Some(ad) = self.adapter.as_mut()
            && self.steps_done.is_multiple_of(ad.config.every)
            && ad.pass(world, self.steps_done)?
        {
            self.mesh_changed(world);
        }
        Ok(true)
    }

    /// The integrate and collide phases of a step; false when the state became
    /// non-finite. The contacts the last step ended in go to the implicit solve
    /// (filtered there, see [`crate::physics::implicit`]).
    fn integrate(&mut self, world: &mut World, h: Scalar) -> bool {
        let air0 = match self.air_power.take() {
            Some(p) => p,
            None => self.stepper.air_power(world),
        };
        let pinned = self.stepper.pinned_start(world);
        if let Some(c) = self.collider.as_mut() {
            c.begin_step(world);
            // Resting contacts from the last step: the vertices are on the surface now.
            self.stepper.contacts.clear();
            self.stepper.contacts.extend_from_slice(c.contacts());
        }
        self.stepper.step(world, h);
        if !is_finite(&world.x) {
            self.failure = StepFailure::NonFinite;
            return false;
        }
        if let Some(c) = self.collider.as_mut() {
            let cloth = StepCloth {
                pushed: &self.stepper.contact_push,
                mass: &self.stepper.elements.mass,
            };
            c.end_step(world, h, cloth, &mut self.collision);
        }
        let air1 = self.stepper.air_power(world);
        self.air_power = Some(air1);
        self.external_work += 0.5 * h * (air0 + air1) + self.stepper.pin_work(&pinned, world, h);
        self.explosion_check(world)
    }

    /// Work done on the cloth from outside so far, J.
    fn work(&self) -> Scalar {
        self.external_work + self.collision.obstacle_work
    }

    /// False (and the failure noted) when the kinetic plus gravitational energy
    /// exceeds the bound by [`EXPLOSION_FACTOR`] scales. Elastic energy is left out
    /// (it is never negative, so the test stays sound) because it costs a pass over
    /// every element, where this costs one over the vertices.
    fn explosion_check(&mut self, world: &World) -> bool {
        let mass = &self.stepper.elements.mass;
        let g = self.stepper.model.external.gravity.unwrap_or(Vector::ZERO);
        let energy = deterministic_sum(world.x.len(), |i| {
            mass[i] * (0.5 * world.v[i].length_squared() - g.dot(world.x[i]))
        });
        let work = self.work();
        let bound = self.bound.initial + work + EXPLOSION_FACTOR * (self.bound.scale + work.abs());
        if energy > bound || !energy.is_finite() {
            self.failure = StepFailure::Explosion { energy, bound };
            return false;
        }
        true
    }

    /// After the world's mesh changed (remeshing, or a restored frame start): rebuild
    /// the force elements, forget the step size and the (now stale) contacts.
    fn mesh_changed(&mut self, world: &World) {
        self.stepper.rebuild(world);
        self.auto_dt = None;
        self.air_power = None;
        if let Some(c) = self.collider.as_mut() {
            c.forget_contacts();
        }
    }
}

/// True when every coordinate is finite (a NaN or infinity anywhere poisons the sum).
fn is_finite(x: &[Vector]) -> bool {
    deterministic_sum(x.len(), |i| x[i].x + x[i].y + x[i].z).is_finite()
}

/// Running statistics for the summary.
struct Tally {
    vertices: Range,
    triangles: Range,
    energy_initial: Scalar,
    energy_final: Scalar,
    energy_max: Scalar,
    mass_initial: Scalar,
    max_level: u8,
}

/// End-of-run facts handed to [`Tally::finish`].
struct TallyEnd<'a> {
    scene: String,
    frames: u64,
    steps: u64,
    sim_time: Scalar,
    wall_time_s: Scalar,
    sim_wall_s: Scalar,
    record_wall_s: Scalar,
    dt: Scalar,
    nan_recoveries: u64,
    interrupted: bool,
    recording: Option<(PathBuf, u64, u64)>,
    stepper: &'a Stepper,
    adapt: Option<AdaptStats>,
    collision: CollisionStats,
    cusick: Option<crate::collide::cusick::CusickSummary>,
    external_work: Scalar,
    excess_max: Scalar,
    energy_retries: u64,
}

impl Tally {
    fn new(world: &World, stepper: &Stepper) -> Tally {
        let e = stepper.energy(world).total();
        Tally {
            vertices: Range::empty(),
            triangles: Range::empty(),
            energy_initial: e,
            energy_final: e,
            energy_max: e,
            mass_initial: stepper.elements.total_mass(),
            max_level: 0,
        }
    }

    fn observe(&mut self, world: &World, e: Energy) {
        self.max_level = self
            .max_level
            .max(world.mesh.levels.iter().copied().max().unwrap_or(0));
        self.vertices.add(world.x.len() as Scalar);
        self.triangles.add(world.mesh.triangles.len() as Scalar);
        self.energy_final = e.total();
        self.energy_max = self.energy_max.max(e.total());
    }

    fn finish(self, end: TallyEnd) -> Summary {
        let vertex_steps = end.steps as Scalar * self.vertices.mean;
        Summary {
            scene: end.scene,
            frames: end.frames,
            steps: end.steps,
            sim_time: end.sim_time,
            wall_time_s: end.wall_time_s,
            simulation_wall_s: end.sim_wall_s,
            recording_wall_s: end.record_wall_s,
            dt: end.dt,
            vertex_steps_per_s: if end.sim_wall_s > 0.0 {
                vertex_steps / end.sim_wall_s
            } else {
                0.0
            },
            vertices: self.vertices,
            triangles: self.triangles,
            mass_initial: self.mass_initial,
            mass_final: end.stepper.elements.total_mass(),
            energy: EnergySummary {
                initial: self.energy_initial,
                r#final: self.energy_final,
                max: self.energy_max,
                external_work: end.external_work,
                excess_max: end.excess_max,
            },
            nan_recoveries: end.nan_recoveries,
            energy_retries: end.energy_retries,
            solver: end.stepper.stats,
            interrupted: end.interrupted,
            splits: end.adapt.map_or(0, |a| a.splits),
            merges: end.adapt.map_or(0, |a| a.merges),
            rollbacks: end.adapt.map_or(0, |a| a.rollbacks),
            max_level: self.max_level,
            adapt: end.adapt,
            max_penetration: end.collision.max_penetration,
            contacts: end.collision.mean_contacts(),
            self_pairs_tested: end.collision.mean_self_pairs_tested(),
            self_culled_fraction: end.collision.self_culled_fraction(),
            collision_wall_s: end.collision.collision_wall_s,
            self_collision_wall_s: end.collision.self_collision_wall_s,
            cusick: end.cusick,
            recording: end.recording.map(|(path, bytes, frames)| RecordingSummary {
                path,
                bytes,
                frames,
            }),
        }
    }
}
