//! The scene a GarmentCode pattern drapes in, written as TOML: the pattern's
//! panels and seams as `[[panel]]` and `[[seam]]`, its held labelled edges as
//! `[[attachment]]` (`attach.rs`), the body as a mesh obstacle, and the
//! draping settings. `drape garment` runs this text and
//! `--write-scene` saves it, so that what runs is what a user can edit.
//!
//! GarmentCode's frame has y up; drape's world has z up. The garment (and a
//! y-up body) is turned by `rotation = [90, 0, 0]`, which maps (x, y, z) to
//! (x, -z, y), Blender's convention for y-up files.

use std::fmt::Write;

use super::Pattern;
use super::attach::{PatternAttachment, RELEASE, STIFFNESS};
use crate::spec::{Curve, Gather, PanelSpec, Placement, SeamDirection, SeamSpec};

/// Which axis of the body file points up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyUp {
    /// y up (GarmentCode's bodies): turned by `rotation = [90, 0, 0]`.
    Y,
    /// z up, as drape's world: not turned.
    Z,
}

/// The body a pattern drapes on.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// The OBJ file as the scene names it (relative to the scene's folder).
    pub path: String,
    /// Which axis of the file points up.
    pub up: BodyUp,
    /// Metres per unit of the file (1 for metres, 0.01 for centimetres).
    pub scale: f64,
}

/// How the garment is meshed, sewn and draped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Draping {
    /// Target edge length of the panels' triangles, m.
    pub max_edge: f64,
    /// The longest simulated time, s.
    pub duration: f64,
    /// Sewing stiffness, N/m per m of seam.
    pub sewing_stiffness: f64,
    /// The gap below which a seam is welded, m.
    pub weld_gap: f64,
    /// Gravity is off while a seam is open, for at most this long, s.
    pub weightless: f64,
    /// The run ends at rest: no vertex faster than this, m/s ...
    pub rest_speed: f64,
    /// ... at any frame end of this long, s.
    pub rest_window: f64,
}

/// The scene of `pattern` (from the file `source`) on `body`, named `name`,
/// with its labelled sides held by `attachments`.
pub fn scene(
    name: &str,
    source: &str,
    pattern: &Pattern,
    attachments: &[PatternAttachment],
    body: &Body,
    d: &Draping,
) -> String {
    let mut s = String::new();
    header(&mut s, name, source, body, d);
    for p in &pattern.panels {
        panel(&mut s, p);
    }
    for seam in &pattern.seams {
        seam_table(&mut s, seam);
    }
    for a in attachments {
        attachment_table(&mut s, a);
    }
    obstacle(&mut s, body);
    s
}

/// An `[[attachment]]` with GarmentCode's stiffness and release time.
fn attachment_table(s: &mut String, a: &PatternAttachment) {
    let sides: Vec<String> = a
        .sides
        .iter()
        .map(|x| format!("  {{ panel = {}, side = {} }},\n", quoted(&x.panel), x.side))
        .collect();
    let _ = write!(
        s,
        "\n[[attachment]]               # GarmentCode holds these edges at the body\nname = {}\nsides = [\n{}]\npoint = {}\nnormal = {}\nstiffness = {:?}             # N/m per m of held side\nrelease = {:?}    # s: GarmentCode's 400 frames at 60 per second\n",
        quoted(&a.name),
        sides.concat(),
        triple(a.point),
        triple(a.normal),
        STIFFNESS,
        RELEASE,
    );
}

/// A TOML string.
fn quoted(s: &str) -> String {
    toml::Value::String(s.to_owned()).to_string()
}

fn point(p: [f64; 2]) -> String {
    format!("[{:?}, {:?}]", p[0], p[1])
}

fn triple(p: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", p[0], p[1], p[2])
}

fn header(s: &mut String, name: &str, source: &str, body: &Body, d: &Draping) {
    let _ = write!(
        s,
        r#"# The GarmentCode pattern {source} on the body {body}, written by
# `drape garment`. Pattern units are metres here; the pattern's frame (y up)
# is turned into drape's z-up world by the cloth's rotation [90, 0, 0].
name = {name}

[simulation]
duration = {duration:?}                 # the longest simulated time, s
frame_rate = 30
integrator = "implicit"
dt = "auto"
gravity = [0.0, 0.0, -9.81]
rest = {{ speed = {rest_speed:?}, window = {rest_window:?} }}  # ends at rest: m/s, s

[cloth]
shape = "panels"
max_edge = {max_edge:?}                # target edge length of the panels' triangles, m
rotation = [90.0, 0.0, 0.0]         # GarmentCode's y up -> drape's z up

[cloth.sewing]
stiffness = {stiffness:?}             # N/m per m of seam
weld_gap = {weld_gap:?}              # m
weightless = {weightless:?}            # gravity off while a seam is open, at most this long, s

[material]
preset = "gray-interlock"           # a t-shirt knit (docs/fabrics.md)
damping = 0.001
"#,
        body = body.path,
        name = quoted(name),
        duration = d.duration,
        max_edge = d.max_edge,
        stiffness = d.sewing_stiffness,
        weld_gap = d.weld_gap,
        weightless = d.weightless,
        rest_speed = d.rest_speed,
        rest_window = d.rest_window,
    );
}

fn panel(s: &mut String, p: &PanelSpec) {
    let outline: Vec<String> = p.outline.iter().map(|c| point(*c)).collect();
    let _ = write!(
        s,
        "\n[[panel]]\nname = {}\noutline = [{}]\n",
        quoted(&p.name),
        outline.join(", ")
    );
    if !p.curves.is_empty() {
        let curves: Vec<String> = p
            .curves
            .iter()
            .map(|c| {
                let rest = match c.curve {
                    Curve::Quadratic { control } => {
                        format!("kind = \"quadratic\", controls = [{}]", point(control))
                    }
                    Curve::Cubic { controls } => format!(
                        "kind = \"cubic\", controls = [{}, {}]",
                        point(controls[0]),
                        point(controls[1])
                    ),
                    Curve::Arc {
                        radius,
                        large_arc,
                        counter_clockwise,
                    } => format!(
                        "kind = \"arc\", radius = {radius:?}, large_arc = {large_arc}, \
                         counter_clockwise = {counter_clockwise}"
                    ),
                };
                format!("  {{ side = {}, {rest} }},\n", c.side)
            })
            .collect();
        let _ = write!(s, "curves = [\n{}]\n", curves.concat());
    }
    match p.placement {
        Placement::Flat { position, rotation } => {
            let _ = write!(
                s,
                "position = {}\nrotation = {}\n",
                triple(position),
                triple(rotation)
            );
        }
        Placement::Cylinder {
            radius,
            angle,
            position,
        } => {
            let _ = write!(
                s,
                "position = {}\nwrap = {{ radius = {radius:?}, angle = {angle:?} }}\n",
                triple(position)
            );
        }
    }
}

fn seam_table(s: &mut String, seam: &SeamSpec) {
    let one = |x: &crate::spec::SeamSide| {
        format!("{{ panel = {}, side = {} }}", quoted(&x.panel), x.side)
    };
    let side = |sides: &[crate::spec::SeamSide]| match sides {
        [x] => one(x),
        many => format!("[{}]", many.iter().map(one).collect::<Vec<_>>().join(", ")),
    };
    let _ = write!(
        s,
        "\n[[seam]]\nname = {}\na = {}\nb = {}\n",
        quoted(&seam.name),
        side(&seam.a),
        side(&seam.b)
    );
    if seam.direction == SeamDirection::Same {
        s.push_str("direction = \"same\"\n");
    }
    if seam.gather == Gather::Any {
        s.push_str("gather = true\n");
    }
}

fn obstacle(s: &mut String, body: &Body) {
    let rotation = match body.up {
        BodyUp::Y => "[90.0, 0.0, 0.0]             # y up -> z up",
        BodyUp::Z => "[0.0, 0.0, 0.0]",
    };
    let _ = write!(
        s,
        "\n[[obstacle]]\nname = \"body\"\nshape = \"mesh\"\npath = {}\nscale = {:?}\nrotation = {rotation}\nthickness = 0.003\nfriction_static = 0.5\nfriction_kinetic = 0.4\n",
        quoted(&body.path),
        body.scale
    );
}
