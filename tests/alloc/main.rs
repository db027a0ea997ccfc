//! Allocations per step in the hot paths: after a
//! warm-up, stepping a scene whose mesh does not change must not touch the heap.
//!
//! A counting global allocator wraps the system one; each case builds a
//! simulation through the public pipeline, advances warm-up frames (scratch buffers
//! grow to their working size, the contact and pair lists reach their peak),
//! then counts the allocations of the next steps. Rayon is pinned to one thread
//! so that its own job bookkeeping cannot be counted; the parallel code paths
//! are the same at any thread count (the determinism tests check their
//! results). This is its own test binary because a global allocator is
//! process-wide. When it fails, `ALLOC_TRACE=1 cargo test --release --test
//! alloc -- --nocapture` prints where each allocation came from.

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use drape::scene::load_scene_file;
use drape::sim::{SimParts, build};

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);
static BYTES: AtomicU64 = AtomicU64::new(0);

// SAFETY: forwards every call to the system allocator unchanged; the counters
// are atomics and allocate nothing.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: the caller upholds `GlobalAlloc::alloc`'s contract.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: as `alloc`.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        // SAFETY: the caller upholds `GlobalAlloc::realloc`'s contract.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// `ALLOC_TRACE=1` in the environment: print a backtrace of every counted
/// allocation (to find a new one when this test fails).
static TRACE: AtomicBool = AtomicBool::new(false);

thread_local! {
    /// Set while a backtrace is taken (it allocates itself).
    static TRACING: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

fn note(bytes: usize) {
    if !COUNTING.load(Ordering::Relaxed) {
        return;
    }
    if TRACE.load(Ordering::Relaxed) {
        TRACING.with(|busy| {
            if !busy.get() {
                busy.set(true);
                let trace = std::backtrace::Backtrace::force_capture();
                eprintln!("allocation of {bytes} bytes:\n{trace}");
                busy.set(false);
            }
        });
    }
    ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    BYTES.fetch_add(bytes as u64, Ordering::Relaxed);
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The frames of the warm-up, s.
const WARM_FRAME: f64 = 1.0 / 30.0;

/// Allocations and bytes of `steps` steps of `scene` (with `overrides`) after
/// `warm` warm-up frames, all at the scene's step size (an adaptive scene adapts
/// during the warm-up only).
fn allocations(scene: &str, overrides: &[&str], warm: usize, steps: usize) -> Count {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let scene = load_scene_file(Path::new(scene), &overrides).expect("scene");
    let SimParts {
        mut setup,
        mut state,
        pipeline: mut pipe,
    } = build(&scene.resolve().expect("resolve")).expect("build");
    let h = pipe.step_size(&setup, &state.world);
    let base_vertices = state.world.x.len();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    pool.install(|| {
        for _ in 0..warm {
            pipe.advance_frame(&setup, &mut state, WARM_FRAME)
                .expect("warm-up frame");
        }
        // Adaptive cases: the mesh adapted during the warm-up and is now frozen
        // (remeshing allocates the new mesh and elements by design). With paper
        // A's rollback the check still runs after every step, in full (no edge
        // can pass an infinite threshold, so it never stops early and never
        // refines).
        let mut rollback_checked = false;
        if let Some(a) = setup.settings.adapt.as_mut() {
            a.every = drape::spec::AdaptEvery::Steps(u32::MAX);
            if a.rollback && a.max_rollbacks > 0 {
                a.refine_angle = f64::INFINITY;
                rollback_checked = true;
            }
        }
        // One step on the frozen mesh before counting: the warm-up's last step
        // may have remeshed, and the solver builds its tables for a new mesh
        // lazily, on its first solve.
        if let Err(e) = pipe.step(&setup, &mut state, h) {
            panic!("step rejected: {e}");
        }
        ALLOCATIONS.store(0, Ordering::Relaxed);
        BYTES.store(0, Ordering::Relaxed);
        let before = state.ledger.collision;
        COUNTING.store(true, Ordering::Relaxed);
        for _ in 0..steps {
            if let Err(e) = pipe.step(&setup, &mut state, h) {
                panic!("step rejected: {e}");
            }
        }
        COUNTING.store(false, Ordering::Relaxed);
        let after = state.ledger.collision;
        Count {
            allocations: ALLOCATIONS.load(Ordering::Relaxed),
            bytes: BYTES.load(Ordering::Relaxed),
            contacts: after.contacts - before.contacts,
            self_pairs: after.self_pairs_tested - before.self_pairs_tested,
            vertices: state.world.x.len(),
            base_vertices,
            rollback_checked,
        }
    })
}

/// What one counted stretch of steps did.
struct Count {
    allocations: u64,
    bytes: u64,
    /// Obstacle contacts over the counted steps.
    contacts: u64,
    /// Self-collision candidate pairs tested over the counted steps.
    self_pairs: u64,
    vertices: usize,
    /// Vertices of the mesh the run started from.
    base_vertices: usize,
    /// Paper A's rollback check ran after every counted step.
    rollback_checked: bool,
}

/// What a case must exercise during its counted steps, so that it tests the
/// path it names.
#[derive(Clone, Copy)]
enum Exercises {
    /// Nothing beyond the integrator.
    Stepping,
    /// Obstacle contacts.
    Contact,
    /// Obstacle contacts and self-collision pairs.
    SelfCollision,
    /// A refined mesh (more vertices than the base mesh), so multirate has
    /// more than one level.
    Refinement,
    /// Paper A's rollback check (edge angles, curvature rule) after each step,
    /// on a refined mesh.
    RollbackCheck,
}

/// Paper A's settings on `scenes/hanging_sheet.toml` (as its header lists
/// them): base 16, two red splits, 15 deg, rollback.
const PAPER_A: [&str; 6] = [
    "cloth.resolution=16",
    "adapt.max_level=4",
    "adapt.refine_angle=15",
    "adapt.coarsen_angle=1.5",
    "adapt.refine_strain=0",
    "adapt.rollback=true",
];

/// One test so that the cases never overlap (the counter is global).
///
/// `deterministic_sum`, which runs several times a step, keeps its chunk sums on
/// the stack; collecting them into a vector would allocate at every step.
#[test]
fn steps_of_an_unchanging_mesh_do_not_allocate() {
    TRACE.store(std::env::var_os("ALLOC_TRACE").is_some(), Ordering::Relaxed);
    let mut failures = Vec::new();
    let mut check = |label: &str, scene: &str, overrides: &[&str], warm, steps, what| {
        let c = allocations(scene, overrides, warm, steps);
        let covered = match what {
            Exercises::Stepping => true,
            Exercises::Contact => c.contacts > 0,
            Exercises::SelfCollision => c.contacts > 0 && c.self_pairs > 0,
            Exercises::Refinement => c.vertices > c.base_vertices,
            Exercises::RollbackCheck => c.rollback_checked && c.vertices > c.base_vertices,
        };
        let seen = format!(
            "{} allocations ({} bytes) in {steps} steps after {warm} warm-up frames ({} \
             vertices, {} at the start; {} obstacle contacts, {} self-collision pairs tested)",
            c.allocations, c.bytes, c.vertices, c.base_vertices, c.contacts, c.self_pairs
        );
        assert!(
            covered,
            "{label}: the counted steps miss the path under test: {seen}"
        );
        if c.allocations != 0 {
            failures.push(format!("{label}: {seen}"));
        }
    };
    // Obstacle contact and friction: the cloth lies on the sphere.
    check(
        "sphere_push, implicit",
        "scenes/sphere_push.toml",
        &[],
        30,
        50,
        Exercises::Contact,
    );
    // Self-collision on the floor: boxes, BVH refit, candidate pairs, impulses.
    // 30 warm-up frames: the per-patch pair lists grow to their peak as the sheet
    // crumples; after only 15, a patch's list can first grow in the counted steps
    // (in `collect_pairs`: growth to a high-water mark, not a per-step allocation).
    check(
        "crumple, uniform, implicit (floor and self-collision)",
        "scenes/crumple.toml",
        &["adapt.method=none"],
        30,
        50,
        Exercises::SelfCollision,
    );
    // Symplectic Euler (the collision pass is the same code as above).
    check(
        "flag, uniform, symplectic Euler",
        "scenes/flag.toml",
        &[
            "adapt.method=none",
            "simulation.integrator=symplectic_euler",
        ],
        3,
        100,
        Exercises::Stepping,
    );
    // RK4 and its stage buffers.
    check(
        "flag, uniform, RK4",
        "scenes/flag.toml",
        &["adapt.method=none"],
        3,
        100,
        Exercises::Stepping,
    );
    // Paper A's multirate stepping (levels, per-level kicks) on an adapted mesh
    // that is not adapted again during the count.
    check(
        "flag, red-green base 16 level 2, multirate RK4",
        "scenes/flag.toml",
        &[
            "adapt.method=red_green",
            "cloth.resolution=16",
            "adapt.max_level=2",
            "adapt.rollback=false",
            "adapt.multirate=true",
        ],
        15,
        100,
        Exercises::Refinement,
    );
    // Paper A's rollback check after every step (it measures the edge angles,
    // and with the sizing rule the leaf curvatures, into reused buffers), on the
    // implicit hanging sheet.
    check(
        "hanging_sheet, red-green with rollback (sizing rule), implicit",
        "scenes/hanging_sheet.toml",
        &PAPER_A,
        40,
        20,
        Exercises::RollbackCheck,
    );
    check(
        "hanging_sheet, red-green with rollback (angle rule), implicit",
        "scenes/hanging_sheet.toml",
        &[&PAPER_A[..], &["adapt.criterion=angle"]].concat(),
        40,
        20,
        Exercises::RollbackCheck,
    );
    assert!(failures.is_empty(), "steps allocated: {failures:?}");
}
