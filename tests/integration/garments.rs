//! Garments: panels from outlines, seams sewn closed and welded into one
//! surface. Sewing closes a seam in bounded time; a weld conserves mass and
//! momentum; a welded seam bends like the panel's interior; the scene's
//! mistakes name the panel or seam; and a garment run is identical at any
//! thread count.

use std::f64::consts::PI;

use drape::garment::{self, BuiltGarment};
use drape::math::{Scalar, Vector};
use drape::physics::forces::energy;
use drape::physics::{Elements, ExternalForces, MaterialParams, Membrane};
use drape::scene::{BendingModel, StiffnessRule, load_scene_str};
use drape::sim::{SeamState, build};
use drape::spec::{Garment, Gather, PanelSpec, Placement, SeamDirection, SeamSide, SeamSpec};
use drape::world::World;

use crate::common::Sim;

fn seam(name: &str, a: (&str, usize), b: (&str, usize)) -> SeamSpec {
    SeamSpec {
        name: name.into(),
        a: vec![SeamSide {
            panel: a.0.into(),
            side: a.1,
        }],
        b: vec![SeamSide {
            panel: b.0.into(),
            side: b.1,
        }],
        direction: SeamDirection::Opposite,
        gather: Gather::None,
    }
}

fn rectangle(name: &str, w: Scalar, h: Scalar, placement: Placement) -> PanelSpec {
    PanelSpec {
        name: name.into(),
        outline: vec![[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]],
        curves: Vec::new(),
        placement,
    }
}

/// Two 0.2 m squares side by side in the xy plane, `gap` apart, the left
/// one's right side sewn to the right one's left side.
pub(crate) const TWO_SQUARES: &str = r#"
name = "two_squares"
[simulation]
duration = 1.0
dt = 0.005
gravity = [0.0, 0.0, 0.0]
[cloth]
shape = "panels"
max_edge = 0.025
[material]
density = 0.2
stretch = 300.0
bending = 2.0e-5
damping = 0.001
[[panel]]
name = "left"
outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]]
position = [-0.22, 0.0, 0.0]
[[panel]]
name = "right"
outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]]
position = [0.02, 0.0, 0.0]
[[seam]]
name = "middle"
a = { panel = "left", side = 2 }
b = { panel = "right", side = 4 }
"#;

/// The simulation of a garment scene given as text, with `--set` overrides.
pub(crate) fn garment_sim(text: &str, sets: &[&str]) -> Sim {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Sim::new(&load_scene_str(text, "garment.toml", &sets).expect("scene"))
}

/// The state of seam `s`.
pub(crate) fn seam_state(sim: &Sim, s: usize) -> SeamState {
    sim.state.seams[s]
}

#[test]
fn sewing_closes_a_two_panel_seam_and_welds_it_within_a_bounded_time() {
    for gap in ["0.02", "0.05"] {
        let set = format!("panel.1.position=[{gap}, 0.0, 0.0]");
        let mut sim = garment_sim(TWO_SQUARES, &[&set]);
        let before = sim.state.world.mesh.vertex_count();
        let pairs = sim.state.world.mesh.panels().expect("panels").seams[0]
            .pairs
            .len();
        let mut steps = 0;
        while seam_state(&sim, 0) == SeamState::Open && steps < 200 {
            sim.step(0.005);
            steps += 1;
        }
        let SeamState::Welded { time } = seam_state(&sim, 0) else {
            panic!("a {gap} m seam still open after 1 s");
        };
        let mesh = &sim.state.world.mesh;
        println!(
            "gap {gap} m: welded at {time:.3} s ({steps} steps), {pairs} pairs, {} -> {} vertices",
            before,
            mesh.vertex_count()
        );
        assert!(time < 0.5, "welded at {time} s");
        assert_eq!(mesh.vertex_count(), before - pairs);
        // The seam is now interior: the only boundary is the outer square's.
        let boundary: Scalar = (0..mesh.edges.len())
            .filter(|&e| !mesh.edges[e].is_interior())
            .map(|e| mesh.rest_length(e))
            .sum();
        println!("boundary length after the weld: {boundary:.6} m (the 0.4 x 0.2 rectangle: 1.2)");
        assert!((boundary - 1.2).abs() < 1e-9, "boundary {boundary}");
    }
}

/// The weld time is simulation state, the pairs mesh topology: a state saved
/// before the weld and restored after it has the seam open again in both.
#[test]
fn restoring_a_state_saved_before_a_weld_reopens_the_seam() {
    let mut sim = garment_sim(TWO_SQUARES, &[]);
    let saved = sim.state.clone();
    let mut steps = 0;
    while seam_state(&sim, 0) == SeamState::Open && steps < 200 {
        sim.step(0.005);
        steps += 1;
    }
    let welded = seam_state(&sim, 0);
    let seam_open = |sim: &Sim| sim.state.world.mesh.panels().expect("panels").seams[0].is_open();
    println!(
        "after {steps} steps: {welded:?}, mesh seam open: {}",
        seam_open(&sim)
    );
    assert!(matches!(welded, SeamState::Welded { time } if time > 0.0));
    assert!(!seam_open(&sim));
    sim.state.restore(&saved);
    assert_eq!(seam_state(&sim, 0), SeamState::Open);
    assert!(seam_open(&sim));
}

#[test]
fn welding_conserves_mass_and_momentum() {
    let mut sim = garment_sim(TWO_SQUARES, &[]);
    let mat = sim.setup.model.material;
    let w = &mut sim.state.world;
    // Each panel moves differently, so merging pairs must average momenta.
    for (i, v) in w.v.iter_mut().enumerate() {
        *v = Vector::new(0.3 * (i % 7) as Scalar - 0.9, 0.1 * (i % 3) as Scalar, -0.2);
    }
    let before = Elements::build(&w.mesh, &mat);
    let momentum = |w: &World, el: &Elements| -> Vector {
        w.v.iter().zip(&el.mass).map(|(v, m)| *v * *m).sum()
    };
    let centre = |w: &World, el: &Elements| -> Vector {
        w.x.iter()
            .zip(&el.mass)
            .map(|(x, m)| *x * *m)
            .sum::<Vector>()
            / el.total_mass()
    };
    let (m0, p0, c0) = (
        before.total_mass(),
        momentum(w, &before),
        centre(w, &before),
    );
    let merged = w.weld_seam(0, &before.mass).expect("weld");
    let after = Elements::build(&w.mesh, &mat);
    let (m1, p1, c1) = (after.total_mass(), momentum(w, &after), centre(w, &after));
    println!(
        "{merged} vertices merged; mass {m0:.15} -> {m1:.15} kg; momentum change {:.3e} kg m/s; centre of mass moved {:.3e} m",
        (p1 - p0).length(),
        (c1 - c0).length()
    );
    assert!(merged > 0);
    assert!((m1 - m0).abs() <= 1e-15 * m0);
    assert!((p1 - p0).length() <= 1e-15 * p0.length().max(1e-3));
    assert!((c1 - c0).length() <= 1e-15);
}

/// Elastic energy of a cylinder of radius `r`, 0.3 m tall, made of `halves`
/// welded panels (1: one panel sewn to itself), bending only.
fn cylinder_bending_energy(halves: usize, r: Scalar, max_edge: Scalar) -> Scalar {
    let width = 2.0 * PI * r / halves as Scalar;
    let names: Vec<String> = (0..halves).map(|k| format!("p{k}")).collect();
    let panels = (0..halves)
        .map(|k| {
            rectangle(
                &names[k],
                width,
                0.3,
                Placement::Cylinder {
                    radius: r,
                    angle: 360.0 * k as Scalar / halves as Scalar,
                    position: [0.0; 3],
                },
            )
        })
        .collect();
    // Panel k's right side (2) to panel k+1's left side (4), around the tube.
    let seams = (0..halves)
        .map(|k| {
            let next = (k + 1) % halves;
            seam(&format!("s{k}"), (&names[k], 2), (&names[next], 4))
        })
        .collect();
    let BuiltGarment { mesh, positions } = garment::build(&Garment {
        panels,
        seams,
        holds: Vec::new(),
        max_edge,
    })
    .expect("garment");
    let mat = MaterialParams {
        density: 0.2,
        stretch: 0.0,
        membrane: Membrane::Springs,
        bending: 1e-3,
        damping: 0.0,
        bending_model: BendingModel::ShapeOperator,
        stiffness_rule: StiffnessRule::Consistent,
        sewing: Default::default(),
    };
    let mut world = World::new(mesh, positions);
    for s in 0..halves {
        let el = Elements::build(&world.mesh, &mat);
        world.weld_seam(s, &el.mass).expect("weld");
    }
    let el = Elements::build(&world.mesh, &mat);
    let ext = ExternalForces::default();
    energy(&el, &ext, &world.x, &world.v).elastic
}

#[test]
fn a_welded_seam_bends_like_the_panel_interior() {
    let r = 0.1;
    // The continuum: B A / (2 R^2) for the whole tube (no free edge along the bend).
    let exact = 1e-3 * (2.0 * PI * r * 0.3) / (2.0 * r * r);
    for max_edge in [0.03, 0.015] {
        let one = cylinder_bending_energy(1, r, max_edge);
        let two = cylinder_bending_energy(2, r, max_edge);
        let three = cylinder_bending_energy(3, r, max_edge);
        println!(
            "max_edge {max_edge}: one panel {one:.6e} J, two halves {two:.6e} J ({:+.3} %), three thirds {three:.6e} J ({:+.3} %); continuum {exact:.6e} J (one panel {:+.3} %)",
            100.0 * (two / one - 1.0),
            100.0 * (three / one - 1.0),
            100.0 * (one / exact - 1.0)
        );
        assert!(
            (two / one - 1.0).abs() < 0.02,
            "two halves {two} vs one {one}"
        );
        assert!(
            (three / one - 1.0).abs() < 0.02,
            "three thirds {three} vs one {one}"
        );
        assert!(
            (one / exact - 1.0).abs() < 0.05,
            "one panel {one} vs {exact}"
        );
    }
}

#[test]
fn open_seams_leave_the_panels_unjoined() {
    // The same tube with its seams left open: no edge joins the two panels
    // until the seams are welded.
    let r = 0.1;
    let welded = cylinder_bending_energy(2, r, 0.03);
    let BuiltGarment { mesh, .. } = garment::build(&Garment {
        panels: vec![
            rectangle(
                "a",
                PI * r,
                0.3,
                Placement::Cylinder {
                    radius: r,
                    angle: 0.0,
                    position: [0.0; 3],
                },
            ),
            rectangle(
                "b",
                PI * r,
                0.3,
                Placement::Cylinder {
                    radius: r,
                    angle: 180.0,
                    position: [0.0; 3],
                },
            ),
        ],
        seams: vec![
            seam("s0", ("a", 2), ("b", 4)),
            seam("s1", ("b", 2), ("a", 4)),
        ],
        holds: Vec::new(),
        max_edge: 0.03,
    })
    .expect("garment");
    let interior_across = mesh
        .edges
        .iter()
        .filter(|e| e.is_interior())
        .filter(|e| {
            mesh.panel_of(e.triangles[0] as usize) != mesh.panel_of(e.triangles[1] as usize)
        })
        .count();
    println!(
        "open seams: {interior_across} edges join the panels; welded tube energy {welded:.6e} J"
    );
    assert_eq!(interior_across, 0);
}

fn edit(from: &str, to: &str) -> String {
    let at = TWO_SQUARES
        .find(from)
        .unwrap_or_else(|| panic!("{from} is not in TWO_SQUARES"));
    format!(
        "{}{to}{}",
        &TWO_SQUARES[..at],
        &TWO_SQUARES[at + from.len()..]
    )
}

#[test]
fn garment_mistakes_name_file_line_and_key() {
    let b = "b = { panel = \"right\", side = 4 }";
    let cases: Vec<(String, &str)> = vec![
        (
            edit(b, "b = { panel = \"rigth\", side = 4 }"),
            "garment.toml:26: key `seam.0.b`: there is no panel `rigth`; allowed: one of: left, right",
        ),
        (
            edit(b, "b = { panel = \"right\", side = 5 }"),
            "garment.toml:26: key `seam.0.b`: panel `right` has sides 1 to 4, not 5",
        ),
        (
            edit(b, "b = { panel = \"left\", side = 2 }"),
            "garment.toml:26: key `seam.0.b`: side 2 of panel `left` is on the seam twice; a panel side is sewn once",
        ),
        (
            edit(
                "outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]]\nposition = [0.02",
                "outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.3], [0.0, 0.3]]\nposition = [0.02",
            ),
            "garment.toml:26: key `seam.0.b`: the sides are 0.2000 m and 0.3000 m long, 33.3 % apart; allowed: sides within 5 % of each other's length",
        ),
        (
            edit("name = \"right\"", "name = \"left\""),
            "key `panel.1.name`: the name `left` is used twice",
        ),
        (
            edit(
                "max_edge = 0.025",
                "max_edge = 0.025\n[adapt]\nmethod = \"tensor\"",
            ),
            "key `adapt.method`: a garment (shape = \"panels\") has no grid lines for the tensor method",
        ),
        (
            edit("max_edge = 0.025\n", ""),
            "missing required key `max_edge` for shape = \"panels\"",
        ),
    ];
    for (text, want) in &cases {
        let err = load_scene_str(text, "garment.toml", &[])
            .err()
            .unwrap_or_else(|| panic!("accepted: {want}"))
            .to_string();
        println!("{err}");
        assert!(err.contains(want), "got: {err}\nwant: {want}");
    }
}

#[test]
fn twisted_seams_self_crossing_outlines_and_panels_inside_a_body_are_refused() {
    let build_err = |text: &str| -> String {
        let scene = load_scene_str(text, "garment.toml", &[]).unwrap_or_else(|e| panic!("{e}"));
        match scene.resolve().map(|spec| build(&spec)) {
            Ok(Ok(_)) => panic!("built"),
            Ok(Err(e)) => e.to_string(),
            Err(e) => e.to_string(),
        }
    };
    // The right panel's outline runs clockwise: its side 1 is the edge next to
    // the left panel, but sewn end to start against the left panel's
    // counter-clockwise side it would join the panels twisted.
    let twisted = edit(
        "outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]]\nposition = [0.02",
        "outline = [[0.0, 0.0], [0.0, 0.2], [0.2, 0.2], [0.2, 0.0]]\nposition = [0.02",
    )
    .replacen("side = 4 }", "side = 1 }", 1);
    let crossing = edit(
        "outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]]\nposition = [-0.22",
        "outline = [[0.0, 0.0], [0.2, 0.2], [0.2, 0.0], [0.0, 0.2]]\nposition = [-0.22",
    );
    let inside = format!(
        "{TWO_SQUARES}[[obstacle]]\nshape = \"sphere\"\nradius = 0.05\nposition = [0.1, 0.1, 0.0]\n"
    );
    for (text, want) in [
        (&twisted, "seam `middle`: it cannot be welded"),
        (
            &crossing,
            "panel `left`: the outline crosses itself: sides 1 and 3 cross or touch",
        ),
        (&inside, "panel `right` starts inside obstacle 0"),
    ] {
        let err = build_err(text);
        println!("{err}");
        assert!(err.contains(want), "got: {err}\nwant: {want}");
    }
}

#[test]
fn the_skirt_sews_and_welds_on_the_mannequin_identically_at_any_thread_count() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/skirt.toml");
    let text = std::fs::read_to_string(path).expect("skirt.toml");
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let mut sim = garment_sim(&text, &[]);
            let vertices = sim.state.world.mesh.vertex_count();
            for _ in 0..30 {
                sim.step(1.0 / 210.0);
            }
            let welded: Vec<SeamState> = (0..2).map(|s| seam_state(&sim, s)).collect();
            (vertices, sim.state.world.x.clone(), welded)
        })
    };
    let (a, b) = (run(1), run(3));
    println!(
        "skirt: {} vertices at the start, {} after 30 steps; seams {:?}",
        a.0,
        a.1.len(),
        a.2
    );
    assert!(a.0 > 1000, "above the parallel thresholds");
    assert!(
        a.2.iter().all(|s| matches!(s, SeamState::Welded { .. })),
        "{:?}",
        a.2
    );
    assert_eq!(a.2, b.2);
    assert!(
        a.1.iter()
            .zip(&b.1)
            .all(|(p, q)| p.to_array() == q.to_array())
    );
}
