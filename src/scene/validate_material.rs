//! Range and consistency checks of `[material]`: the fabric's moduli, its
//! bending given one way, and the triangle membrane's keys only where they apply.

use toml::Table;

use super::error::{Issue, SceneErrorKind as Kind, keys};
use super::validate::{non_negative, positive};
use super::{Material, MembraneModel};

/// The first problem in `[material]`, if any; `written` is the section as the
/// document has it (to tell keys written from defaults).
pub(super) fn material(
    m: &Material,
    written: Option<&Table>,
    gravity: [f64; 3],
) -> Result<(), Issue> {
    let at = |k: &str| keys(&["material", k]);
    positive(at("density"), m.density)?;
    positive(at("stretch"), m.stretch)?;
    moduli(m)?;
    non_negative(at("bending"), m.bending)?;
    if let Some(c) = m.bending_length {
        if written.is_some_and(|t| t.contains_key("bending")) {
            return Err(Issue::new(
                at("bending_length"),
                Kind::NotApplicable,
                "`bending_length` and `bending` both given: they set the same rigidity",
            )
            .allowed("exactly one of `bending` (N m) and `bending_length` (m)")
            .because(at("bending")));
        }
        positive(at("bending_length"), c)?;
        if gravity.iter().all(|&g| g == 0.0) {
            return Err(Issue::new(
                at("bending_length"),
                Kind::NotApplicable,
                "`bending_length` needs gravity to convert to a rigidity (B = density |g| c^3), and gravity is zero",
            )
            .allowed("`bending` (N m) in a scene without gravity")
            .because(keys(&["simulation", "gravity"])));
        }
    }
    non_negative(at("damping"), m.damping)
}

/// The triangle membrane's `warp`, `weft` and `shear`: positive, and only with
/// `membrane = "triangles"` (the springs have one constant, `stretch`).
fn moduli(m: &Material) -> Result<(), Issue> {
    let at = |k: &str| keys(&["material", k]);
    for (key, value) in [("warp", m.warp), ("weft", m.weft), ("shear", m.shear)] {
        let Some(value) = value else { continue };
        if m.membrane != MembraneModel::Triangles {
            return Err(Issue::new(
                at(key),
                Kind::NotApplicable,
                format!("`{key}` is a modulus of the triangle membrane; the springs have one constant, `stretch`"),
            )
            .allowed("membrane = \"triangles\" with warp, weft and shear, or `stretch` alone")
            .because(at("membrane")));
        }
        positive(at(key), value)?;
    }
    Ok(())
}
