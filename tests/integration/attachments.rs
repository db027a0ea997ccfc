//! Attachments (`[[attachment]]`): a held panel side is kept on its side of
//! the attachment's plane until the release time and falls after it; the held
//! vertices follow the side through a weld and a red-green remesh; bad
//! attachment tables are refused naming their line and key.

use drape::adapt::red_green::RedGreenOp;
use drape::adapt::{AdaptConfig, Adapter};
use drape::garment::{self, BuiltGarment};
use drape::math::Scalar;
use drape::mesh::Mesh;
use drape::physics::{Elements, MaterialParams, Membrane};
use drape::scene::{AdaptMethod, BendingModel, SceneErrorKind as Kind, StiffnessRule};
use drape::spec::{
    Garment, Gather, HoldSpec, PanelSpec, Placement, SeamDirection, SeamSide, SeamSpec,
};
use drape::world::World;

use crate::common::angle_config;
use crate::garments::garment_sim;

/// A 0.2 m square hanging in the xz plane, its top side (side 3) at z = 1 m
/// held above the plane z = 1 m until 0.3 s.
const HANGING: &str = r#"
name = "hanging"
[simulation]
duration = 1.0
dt = 0.005
gravity = [0.0, 0.0, -9.81]
[cloth]
shape = "panels"
max_edge = 0.025
[material]
density = 0.2
stretch = 300.0
bending = 2.0e-5
damping = 0.001
[[panel]]
name = "sheet"
outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]]
position = [0.0, 0.0, 0.8]
rotation = [90.0, 0.0, 0.0]
[[attachment]]
name = "waist"
sides = [{ panel = "sheet", side = 3 }]
point = [0.0, 0.0, 1.0]
normal = [0.0, 0.0, 1.0]
stiffness = 1000.0
release = 0.3
"#;

/// The lowest and highest z of the held vertices.
fn held_z(world: &World) -> (Scalar, Scalar) {
    let chains = &world.mesh.holds()[0].chains;
    let z = chains.iter().flatten().map(|&v| world.x[v as usize].z);
    z.clone().fold((Scalar::MAX, Scalar::MIN), |(lo, hi), z| {
        (lo.min(z), hi.max(z))
    })
}

#[test]
fn a_held_side_stays_at_its_plane_while_attached_and_falls_after_release() {
    let mut sim = garment_sim(HANGING, &[]);
    let held = sim.state.world.mesh.holds()[0].chains[0].len();
    assert!(held >= 9, "the 0.2 m side at 25 mm holds {held} vertices");
    let mut deepest: Scalar = 0.0;
    while sim.state.world.time < 0.3 - 1e-9 {
        sim.step(0.005);
        deepest = deepest.max(1.0 - held_z(&sim.state.world).0);
    }
    let lowest = sim
        .state
        .world
        .x
        .iter()
        .map(|x| x.z)
        .fold(Scalar::MAX, Scalar::min);
    println!(
        "held for 0.3 s: deepest below the plane {:.3} mm; sheet down to z = {lowest:.4} m",
        1e3 * deepest
    );
    // Its weight (7.8 mN over 0.2 m) sinks the side 0.4 mm at 1000 N/m per m;
    // unheld, it would have fallen 0.44 m by now.
    assert!(
        deepest < 2e-3,
        "the held side sank {deepest} m below its plane"
    );
    assert!(lowest > 0.75, "the sheet fell to {lowest} m while held");
    let after = sim.state.world.time;
    while sim.state.world.time < after + 0.2 - 1e-9 {
        sim.step(0.005);
    }
    let (_, top) = held_z(&sim.state.world);
    println!("0.2 s after the release the side is at z <= {top:.4} m");
    // Free fall for 0.2 s drops 0.196 m.
    assert!(top < 0.85, "released, the side is still at {top} m");
}

/// Two 0.2 m squares side by side, the left's side 2 sewn to the right's side
/// 4, both top sides (side 3) held by one attachment.
fn held_squares() -> BuiltGarment {
    let square = |name: &str, x: Scalar| PanelSpec {
        name: name.into(),
        outline: vec![[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]],
        curves: Vec::new(),
        placement: Placement::Flat {
            position: [x, 0.0, 0.0],
            rotation: [0.0; 3],
        },
    };
    let side = |panel: &str, side| SeamSide {
        panel: panel.into(),
        side,
    };
    garment::build(&Garment {
        panels: vec![square("left", -0.2), square("right", 0.0)],
        seams: vec![SeamSpec {
            name: "middle".into(),
            a: vec![side("left", 2)],
            b: vec![side("right", 4)],
            direction: SeamDirection::Opposite,
            gather: Gather::None,
        }],
        holds: vec![HoldSpec {
            name: "top".into(),
            sides: vec![side("left", 3), side("right", 3)],
        }],
        max_edge: 0.05,
    })
    .expect("garment")
}

/// Checks that the hold's chains are exactly the mesh's top boundary (every
/// vertex at pattern v = 0.2, neighbours joined by a boundary edge, every
/// boundary vertex at the top in a chain); returns the held vertices.
fn check_top_held(mesh: &Mesh) -> usize {
    let chains = &mesh.holds()[0].chains;
    let boundary = |a: u32, b: u32| {
        let key = [a.min(b), a.max(b)];
        mesh.edges
            .iter()
            .any(|e| e.vertices == key && !e.is_interior())
    };
    let mut held: Vec<u32> = chains.iter().flatten().copied().collect();
    for &v in &held {
        let y = mesh.material[v as usize].y;
        assert!((y - 0.2).abs() < 1e-12, "held vertex {v} lies at v = {y}");
    }
    for c in chains {
        for w in c.windows(2) {
            assert!(
                boundary(w[0], w[1]),
                "held neighbours {w:?} share no boundary edge"
            );
        }
    }
    held.sort_unstable();
    held.dedup();
    let mut top: Vec<u32> = mesh
        .edges
        .iter()
        .filter(|e| !e.is_interior())
        .flat_map(|e| e.vertices)
        .filter(|&v| (mesh.material[v as usize].y - 0.2).abs() < 1e-12)
        .collect();
    top.sort_unstable();
    top.dedup();
    assert_eq!(held, top, "the held vertices are not the top side's");
    held.len()
}

#[test]
fn held_vertices_survive_a_weld_and_a_red_green_remesh() {
    let BuiltGarment { mesh, positions } = held_squares();
    let open = check_top_held(&mesh);
    let mat = MaterialParams {
        density: 0.2,
        stretch: 300.0,
        membrane: Membrane::Springs,
        bending: 1e-3,
        damping: 0.0,
        bending_model: BendingModel::ShapeOperator,
        stiffness_rule: StiffnessRule::Consistent,
        sewing: Default::default(),
    };
    let mut world = World::new(mesh, positions);
    let el = Elements::build(&world.mesh, &mat);
    world.weld_seam(0, &el.mass).expect("weld");
    let welded = check_top_held(&world.mesh);
    // The two top corners on the seam become one vertex.
    assert_eq!(welded, open - 1);
    let c = AdaptConfig {
        max_level: 3,
        ..angle_config(AdaptMethod::RedGreen)
    };
    let mut ad = Adapter::new(&c, &world, 0.2).expect("red-green on a welded garment");
    for round in 0..2 {
        let leaves = ad.hierarchy().expect("red-green").leaves();
        let ops: Vec<_> = leaves
            .iter()
            .map(|&l| (RedGreenOp::Split(l), None))
            .collect();
        ad.apply(&c, &mut world, &ops, round).expect("refine");
    }
    let refined = check_top_held(&world.mesh);
    println!("held vertices: {open} open, {welded} welded, {refined} refined twice");
    assert_eq!(
        refined,
        4 * (welded - 1) + 1,
        "each top segment split in four"
    );
}

#[test]
fn an_attachment_naming_a_missing_panel_or_side_is_refused_at_its_line() {
    let line = |text: &str, key: &str| {
        HANGING
            .lines()
            .position(|l| l.starts_with(text))
            .map(|i| i + 1)
            .unwrap_or_else(|| panic!("test bug: no line {text} for {key}"))
    };
    let cases = [
        (
            HANGING.replace(
                "{ panel = \"sheet\", side = 3 }",
                "{ panel = \"shet\", side = 3 }",
            ),
            "sides = ",
            "attachment.0.sides.0",
            Kind::BadValue,
            "there is no panel `shet`",
        ),
        (
            HANGING.replace(
                "{ panel = \"sheet\", side = 3 }",
                "{ panel = \"sheet\", side = 5 }",
            ),
            "sides = ",
            "attachment.0.sides.0",
            Kind::OutOfRange,
            "panel `sheet` has sides 1 to 4, not 5",
        ),
        (
            HANGING.replace("normal = [0.0, 0.0, 1.0]", "normal = [0.0, 0.0, 0.0]"),
            "normal = ",
            "attachment.0.normal",
            Kind::BadValue,
            "the normal is zero",
        ),
        (
            HANGING.replace("release = 0.3", "release = -1.0"),
            "release = ",
            "attachment.0.release",
            Kind::OutOfRange,
            "",
        ),
        (
            HANGING.replace("stiffness = 1000.0", "stiffness = 0.0"),
            "stiffness = ",
            "attachment.0.stiffness",
            Kind::OutOfRange,
            "",
        ),
    ];
    for (text, at, key, kind, words) in cases {
        let e = drape::scene::load_scene_str(&text, "test.toml", &[]).expect_err(key);
        let msg = e.to_string();
        println!("{msg}");
        assert_eq!(e.kind, kind, "{msg}");
        assert_eq!(e.key.as_deref(), Some(key), "{msg}");
        assert_eq!(e.line, Some(line(at, key)), "{msg}");
        assert!(msg.starts_with("test.toml:"), "{msg}");
        assert!(msg.contains(words), "{msg}");
    }
}

#[test]
fn an_attachment_on_a_cloth_without_panels_is_refused() {
    let text = "name = \"t\"\n[simulation]\nduration = 1.0\n[cloth]\nshape = \"rectangle\"\n\
                width = 1.0\nheight = 1.0\nresolution = 4\n[material]\ndensity = 0.1\n\
                stretch = 100.0\n[[attachment]]\nname = \"a\"\nsides = [{ panel = \"p\", side = 1 }]\n\
                point = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n";
    let e = drape::scene::load_scene_str(text, "test.toml", &[]).expect_err("not panels");
    let msg = e.to_string();
    assert_eq!(e.kind, Kind::NotApplicable, "{msg}");
    assert_eq!(e.line, Some(13), "{msg}");
}
