//! Checks of a garment's `[[panel]]`, `[[seam]]` and `[[attachment]]` tables:
//! names, outlines, placements, seams that name existing panel sides of
//! matching length, and attachments that name existing sides and a plane;
//! and of `[cloth.sewing]`, which sews both these seams and an OBJ's.
//! Each check names the key path, which `parse.rs` turns into a line of the
//! file or a `--set`.

use super::error::{Issue, KeyPath, SceneErrorKind as Kind, Seg, keys};
use super::model::{PanelTable, SeamTable, SewingTable};
use super::validate::{all_finite, non_negative, positive};
use super::{ClothShape, Scene};
use crate::garment::SEAM_LENGTH_TOLERANCE;
use crate::math::Scalar;
use crate::spec::{AdaptMethod, AttachmentTable, Curve, SeamEdge, SeamSide};

fn at(table: &str, i: usize, key: &str) -> KeyPath {
    vec![Seg::Key(table.into()), Seg::Index(i), Seg::Key(key.into())]
}

/// The garment tables: present exactly when `shape = "panels"`, and sound.
pub(super) fn garment(scene: &Scene) -> Result<(), Issue> {
    let panels_shape = scene.cloth.shape == ClothShape::Panels;
    if !panels_shape {
        for (table, count) in [
            ("panel", scene.panel.len()),
            ("seam", scene.seam.len()),
            ("attachment", scene.attachment.len()),
        ] {
            if count > 0 {
                return Err(Issue::new(
                    at(table, 0, "name"),
                    Kind::NotApplicable,
                    format!("[[{table}]] applies to shape = \"panels\" only"),
                )
                .because(keys(&["cloth", "shape"])));
            }
        }
        return Ok(());
    }
    if scene.panel.is_empty() {
        return Err(Issue::new(
            keys(&["panel"]),
            Kind::MissingKey,
            "shape = \"panels\" needs at least one [[panel]]",
        )
        .because(keys(&["cloth", "shape"])));
    }
    if scene.adapt.as_ref().map(|a| a.method) == Some(AdaptMethod::Tensor) {
        return Err(Issue::new(
            keys(&["adapt", "method"]),
            Kind::Unsupported,
            "a garment (shape = \"panels\") has no grid lines for the tensor method to \
             insert or remove",
        )
        .allowed("method = \"red_green\", \"edge\" or \"none\"")
        .because(keys(&["cloth", "shape"])));
    }
    for (i, p) in scene.panel.iter().enumerate() {
        panel(i, p, &scene.panel[..i])?;
    }
    for (i, s) in scene.seam.iter().enumerate() {
        seam(i, s, &scene.seam[..i], &scene.panel)?;
    }
    for (i, a) in scene.attachment.iter().enumerate() {
        attachment(i, a, &scene.attachment[..i], &scene.panel)?;
    }
    Ok(())
}

/// Checks `[[attachment]]` number `i` (`a`): a unique name, existing panel
/// sides, a plane with a finite point and a non-zero normal, a positive
/// stiffness and a release time >= 0.
fn attachment(
    i: usize,
    a: &AttachmentTable,
    earlier: &[AttachmentTable],
    panels: &[PanelTable],
) -> Result<(), Issue> {
    let path = |key: &str| at("attachment", i, key);
    unique_name(
        path("name"),
        &a.name,
        earlier.iter().map(|e| e.name.clone()),
    )?;
    if a.sides.is_empty() {
        return Err(Issue::new(
            path("sides"),
            Kind::BadValue,
            "an attachment holds at least one panel side",
        ));
    }
    for (k, side) in a.sides.iter().enumerate() {
        let mut at_side = path("sides");
        at_side.push(Seg::Index(k));
        existing_side(at_side, side, panels)?;
    }
    all_finite(path("point"), &a.point)?;
    all_finite(path("normal"), &a.normal)?;
    if a.normal.iter().all(|&c| c == 0.0) {
        return Err(Issue::new(
            path("normal"),
            Kind::BadValue,
            "the normal is zero: it must give the side of the plane the sides are held on",
        ));
    }
    positive(path("stiffness"), a.stiffness)?;
    match a.release {
        Some(t) => non_negative(path("release"), t),
        None => Ok(()),
    }
}

/// `[cloth.sewing]`: a positive, finite stiffness, weld gap and (when given)
/// maximum force.
pub(super) fn sewing(s: &SewingTable) -> Result<(), Issue> {
    let at = |key: &str| keys(&["cloth", "sewing", key]);
    positive(at("stiffness"), s.stiffness)?;
    positive(at("weld_gap"), s.weld_gap)?;
    if let Some(t) = s.weightless {
        positive(at("weightless"), t)?;
    }
    match s.max_force {
        Some(f) => positive(at("max_force"), f),
        None => Ok(()),
    }
}

fn unique_name(
    path: KeyPath,
    name: &str,
    earlier: impl Iterator<Item = String>,
) -> Result<(), Issue> {
    if name.trim().is_empty() {
        return Err(Issue::new(path, Kind::BadValue, "the name is empty"));
    }
    for other in earlier {
        if other == name {
            return Err(Issue::new(
                path,
                Kind::BadValue,
                format!("the name `{name}` is used twice"),
            ));
        }
    }
    Ok(())
}

fn panel(i: usize, p: &PanelTable, earlier: &[PanelTable]) -> Result<(), Issue> {
    unique_name(
        at("panel", i, "name"),
        &p.name,
        earlier.iter().map(|e| e.name.clone()),
    )?;
    if p.outline.len() < 3 {
        return Err(Issue::new(
            at("panel", i, "outline"),
            Kind::BadValue,
            format!(
                "an outline needs at least 3 corners, this one has {}",
                p.outline.len()
            ),
        ));
    }
    let flat: Vec<f64> = p.outline.iter().flatten().copied().collect();
    all_finite(at("panel", i, "outline"), &flat)?;
    all_finite(at("panel", i, "position"), &p.position)?;
    curves(i, p)?;
    match (&p.wrap, &p.rotation) {
        (Some(_), Some(_)) => Err(Issue::new(
            at("panel", i, "rotation"),
            Kind::NotApplicable,
            "`rotation` does not apply to a wrapped panel (the cylinder places it)",
        )
        .because(at("panel", i, "wrap"))),
        (Some(w), None) => {
            let mut path = at("panel", i, "wrap");
            path.push(Seg::Key("radius".into()));
            positive(path, w.radius)?;
            let mut path = at("panel", i, "wrap");
            path.push(Seg::Key("angle".into()));
            all_finite(path, &[w.angle])
        }
        (None, Some(r)) => all_finite(at("panel", i, "rotation"), r),
        (None, None) => Ok(()),
    }
}

/// Each curve names an existing side, one curve per side, with finite
/// control points and a positive arc radius.
fn curves(i: usize, p: &PanelTable) -> Result<(), Issue> {
    let n = p.outline.len();
    for (k, c) in p.curves.iter().enumerate() {
        let mut path = at("panel", i, "curves");
        path.push(Seg::Index(k));
        let bad = |what: String| Err(Issue::new(path.clone(), Kind::BadValue, what));
        if c.side == 0 || c.side > n {
            return Err(Issue::new(
                path,
                Kind::OutOfRange,
                format!("the panel has sides 1 to {n}, not {}", c.side),
            )
            .allowed(format!(
                "1 to {n}: side k runs from outline corner k to corner k + 1"
            )));
        }
        if p.curves[..k].iter().any(|e| e.side == c.side) {
            return bad(format!("side {} has two curves", c.side));
        }
        match c.curve {
            Curve::Quadratic { control } => all_finite(path, &control)?,
            Curve::Cubic { controls } => all_finite(path, controls.as_flattened())?,
            Curve::Arc { radius, .. } => positive(path, radius)?,
        }
    }
    Ok(())
}

/// Checks `[[seam]]` number `i` (`s`) against the panels and the seams before it.
fn seam(
    i: usize,
    s: &SeamTable,
    earlier: &[SeamTable],
    panels: &[PanelTable],
) -> Result<(), Issue> {
    unique_name(
        at("seam", i, "name"),
        &s.name,
        earlier.iter().map(|e| e.name.clone()),
    )?;
    let length = [
        edge_length(i, "a", &s.a, panels)?,
        edge_length(i, "b", &s.b, panels)?,
    ];
    let sides: Vec<&SeamSide> = s.a.sides().iter().chain(s.b.sides()).collect();
    if let Some((k, side)) = sides
        .iter()
        .enumerate()
        .find(|(k, side)| sides[..*k].contains(side))
    {
        let key = if k < s.a.sides().len() { "a" } else { "b" };
        return Err(Issue::new(
            at("seam", i, key),
            Kind::BadValue,
            format!(
                "side {} of panel `{}` is on the seam twice; a panel side is sewn once",
                side.side, side.panel
            ),
        ));
    }
    not_sewn_before(i, s, earlier)?;
    seam_lengths_match(i, s, panels, length)
}

/// The length of the edge `edge` (its sides' straight lengths summed), key
/// `key` of `[[seam]]` number `i`, or the issue when it has no side or names
/// a panel or side that is not there.
fn edge_length(
    i: usize,
    key: &str,
    edge: &SeamEdge,
    panels: &[PanelTable],
) -> Result<Scalar, Issue> {
    if edge.sides().is_empty() {
        return Err(Issue::new(
            at("seam", i, key),
            Kind::BadValue,
            "the array of panel sides is empty",
        )
        .allowed("one table { panel, side } or a non-empty array of them"));
    }
    let mut length = 0.0;
    for side in edge.sides() {
        let p = existing_side(at("seam", i, key), side, panels)?;
        let n = p.outline.len();
        let (u, w) = (p.outline[side.side - 1], p.outline[side.side % n]);
        length += (u[0] - w[0]).hypot(u[1] - w[1]);
    }
    Ok(length)
}

/// The panel of `side` (the key at `path`), or the issue when there is no
/// such panel or side.
fn existing_side<'a>(
    path: KeyPath,
    side: &SeamSide,
    panels: &'a [PanelTable],
) -> Result<&'a PanelTable, Issue> {
    let Some(p) = panels.iter().find(|p| p.name == side.panel) else {
        let names: Vec<&str> = panels.iter().map(|p| p.name.as_str()).collect();
        return Err(Issue::new(
            path,
            Kind::BadValue,
            format!("there is no panel `{}`", side.panel),
        )
        .allowed(format!("one of: {}", names.join(", "))));
    };
    let n = p.outline.len();
    if side.side == 0 || side.side > n {
        return Err(Issue::new(
            path,
            Kind::OutOfRange,
            format!("panel `{}` has sides 1 to {n}, not {}", p.name, side.side),
        )
        .allowed(format!(
            "1 to {n}: side k runs from outline corner k to corner k + 1"
        )));
    }
    Ok(p)
}

/// The issue when a side of `[[seam]]` number `i` (`s`) is sewn by an earlier seam.
fn not_sewn_before(i: usize, s: &SeamTable, earlier: &[SeamTable]) -> Result<(), Issue> {
    for (j, e) in earlier.iter().enumerate() {
        let sewn = |side: &SeamSide| e.a.sides().contains(side) || e.b.sides().contains(side);
        for (key, edge) in [("a", &s.a), ("b", &s.b)] {
            if let Some(side) = edge.sides().iter().find(|side| sewn(side)) {
                return Err(Issue::new(
                    at("seam", i, key),
                    Kind::BadValue,
                    format!(
                        "side {} of panel `{}` is already sewn by seam `{}` ([[seam]] {})",
                        side.side,
                        side.panel,
                        e.name,
                        j + 1
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The issue when the straight sides of `[[seam]]` number `i` (`s`), `length`
/// long, differ by more than [`SEAM_LENGTH_TOLERANCE`] without `gather`.
fn seam_lengths_match(
    i: usize,
    s: &SeamTable,
    panels: &[PanelTable],
    length: [Scalar; 2],
) -> Result<(), Issue> {
    let curved = s.a.sides().iter().chain(s.b.sides()).any(|side| {
        panels
            .iter()
            .find(|p| p.name == side.panel)
            .is_some_and(|p| p.curves.iter().any(|c| c.side == side.side))
    });
    if s.gather || curved {
        // A curved side's length is checked where the garment is built.
        return Ok(());
    }
    let (la, lb) = (length[0], length[1]);
    if (la - lb).abs() > SEAM_LENGTH_TOLERANCE * la.max(lb) {
        return Err(Issue::new(
            at("seam", i, "b"),
            Kind::BadValue,
            format!(
                "the sides are {la:.4} m and {lb:.4} m long, {:.1} % apart",
                100.0 * (la - lb).abs() / la.max(lb)
            ),
        )
        .allowed(format!(
            "sides within {:.0} % of each other's length (they are sewn point to point), \
             or `gather = true`",
            100.0 * SEAM_LENGTH_TOLERANCE
        )));
    }
    Ok(())
}
