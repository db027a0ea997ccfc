//! Named fabrics from published measurements (`material.preset`).
//!
//! The ten fabrics of Wang, O'Brien and Ramamoorthi (2011, "Data-driven
//! elastic models for cloth: modeling and measurement", ACM Transactions on
//! Graphics 30(4)), as their database is distributed with ARCSim
//! (`materials/NAME.json`, read through ARCSim 0.2.1's `conf.cpp`, `dde.cpp`
//! and `physics.cpp`). Each entry keeps the file's numbers that the small-strain
//! linearisation needs; [`Fabric`]'s methods convert them to drape's moduli.
//!
//! # The conversion (derivation in `docs/fabrics.md`)
//! - `stretching`: ARCSim reads the file's first row as the zero-strain sample
//!   `[k0, k1, k2, k3]` (the other five rows are the samples at a principal
//!   stretch of 7/6 along five directions) and doubles every entry
//!   (`evaluate_stretching_sample`); its forces are the gradient of
//!   `(2k0 G00^2 + 4k1 G00 G11 + 2k2 G11^2) / 2 + 2k3 G01^2` per area (Green
//!   strain `G`, the file's `k`). drape's energy is
//!   `(warp E_uu^2 + weft E_vv^2 + shear g^2) / 2` with `g = 2 G01`, so
//!   `warp = 2 k0`, `weft = 2 k2`, `shear = k3`; the coupling `2 k1` has no
//!   place in drape's membrane (Poisson ratio 0) and is dropped.
//! - `bending`: three rows (hinge edges along u, at 45 deg, along v) of five
//!   curvature samples, the first at zero curvature. ARCSim's hinge energy is
//!   `ke L^2 / (2 (A1 + A2)) theta^2 / 4`; drape's dihedral hinge is
//!   `(B/2) theta^2 L^2 / (A1 + A2)`, exact for the plate of rigidity `B`, so
//!   `B = ke / 4`. A strip bent along u folds about hinges along v (the third
//!   row), one bent along v about hinges along u (the first row); drape has one
//!   rigidity, their mean.

use toml::{Table, Value};

use super::error::{Issue, SceneErrorKind as Kind, keys};

/// One measured fabric: ARCSim's numbers at zero strain and zero curvature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fabric {
    /// The preset's name, ARCSim's file name without `.json`.
    pub name: &'static str,
    /// What the fabric is made into and of (the database's README).
    pub description: &'static str,
    /// Area density, kg/m^2 (the file's `density`).
    pub density: f64,
    /// The file's first `stretching` row `[k0, k1, k2, k3]`, N/m before
    /// ARCSim's doubling.
    pub stretching: [f64; 4],
    /// The first column of the file's three `bending` rows (hinges along u,
    /// at 45 deg, along v), N m.
    pub bending: [f64; 3],
}

impl Fabric {
    /// Tensile stiffness along u at zero strain, N/m: `2 k0`.
    pub fn warp(&self) -> f64 {
        2.0 * self.stretching[0]
    }

    /// Tensile stiffness along v at zero strain, N/m: `2 k2`.
    pub fn weft(&self) -> f64 {
        2.0 * self.stretching[2]
    }

    /// In-plane shear stiffness at zero strain, N/m per unit shear angle:
    /// `k3` (module docs).
    pub fn shear(&self) -> f64 {
        self.stretching[3]
    }

    /// The warp-weft coupling `2 k1` (N/m, negative values clamped to zero as
    /// ARCSim does) that drape's membrane leaves out.
    pub fn dropped_coupling(&self) -> f64 {
        (2.0 * self.stretching[1]).max(0.0)
    }

    /// Bending rigidity of a strip along u (curved along u, folding about
    /// hinges along v), N m: a quarter of the third `bending` row's first value.
    pub fn bending_u(&self) -> f64 {
        self.bending[2] / 4.0
    }

    /// Bending rigidity of a strip along v, N m: a quarter of the first
    /// `bending` row's first value.
    pub fn bending_v(&self) -> f64 {
        self.bending[0] / 4.0
    }

    /// The one rigidity drape uses, N m: the mean of [`Fabric::bending_u`]
    /// and [`Fabric::bending_v`].
    pub fn rigidity(&self) -> f64 {
        0.5 * (self.bending_u() + self.bending_v())
    }

    /// The springs' one constant when a scene asks for `membrane = "springs"`
    /// with this preset, N/m: the mean of warp and weft.
    pub fn stretch(&self) -> f64 {
        0.5 * (self.warp() + self.weft())
    }
}

/// The ten fabrics, each from ARCSim's `materials/NAME.json` (Wang, O'Brien
/// and Ramamoorthi 2011), in order of area density.
pub const FABRICS: [Fabric; 10] = [
    Fabric {
        // materials/tango-red-jet-set.json
        name: "tango-red-jet-set",
        description: "jacket; 100% polyester",
        density: 0.113,
        stretching: [43.067627, 54.373299, 171.424835, 14.3147],
        bending: [14.293814e-6, 21.9517e-6, 20.345654e-6],
    },
    Fabric {
        // materials/white-dots-on-blk.json
        name: "white-dots-on-blk",
        description: "tablecloth; 100% polyester",
        density: 0.128,
        stretching: [2002.08618, 0.345588, 2027.48559, 19.189022],
        bending: [51.713814e-6, 40.65947e-6, 31.282822e-6],
    },
    Fabric {
        // materials/gray-interlock.json
        name: "gray-interlock",
        description: "t-shirt; 60% cotton, 40% polyester",
        density: 0.187,
        stretching: [16.593832, -14.69599, 34.477123, 36.860302],
        bending: [23.191698e-6, 24.749964e-6, 14.267624e-6],
    },
    Fabric {
        // materials/white-swim-solid.json
        name: "white-swim-solid",
        description: "swimsuit; 87% nylon, 13% spandex",
        density: 0.204,
        stretching: [47.971176, 6.834521, 104.615456, 60.773663],
        bending: [60.237942e-6, 58.803211e-6, 51.018833e-6],
    },
    Fabric {
        // materials/royal-target.json
        name: "royal-target",
        description: "pants; 65% cotton, 35% polyester",
        density: 0.22,
        stretching: [2016.55456, 9.170511, 2034.97644, 104.759674],
        bending: [125.409805e-6, 107.997696e-6, 125.409805e-6],
    },
    Fabric {
        // materials/navy-sparkle-sweat.json
        name: "navy-sparkle-sweat",
        description: "sweater; 96% polyester, 4% spandex",
        density: 0.224,
        stretching: [12.486332, -19.875324, 3.272434, 17.616289],
        bending: [59.469658e-6, 40.072277e-6, 45.625023e-6],
    },
    Fabric {
        // materials/pink-ribbon-brown.json
        name: "pink-ribbon-brown",
        description: "blanket; 100% polyester",
        density: 0.228,
        stretching: [151.503906, 106.02816, 244.830673, 30.250183],
        bending: [117.070122e-6, 87.509773e-6, 59.774277e-6],
    },
    Fabric {
        // materials/ivory-rib-knit.json
        name: "ivory-rib-knit",
        description: "underwear; 95% cotton, 5% spandex",
        density: 0.276,
        stretching: [42.871021, -0.234556, 65.166023, 83.175644],
        bending: [46.237591e-6, 30.01593e-6, 32.243889e-6],
    },
    Fabric {
        // materials/camel-ponte-roma.json
        name: "camel-ponte-roma",
        description: "jacket; 60% polyester, 40% rayon",
        density: 0.284,
        stretching: [31.146198, -12.802702, 44.028667, 31.896357],
        bending: [36.348366e-6, 33.013252e-6, 37.157593e-6],
    },
    Fabric {
        // materials/11oz-black-denim.json
        name: "11oz-black-denim",
        description: "jeans; 99% cotton, 1% spandex",
        density: 0.324,
        stretching: [205.352005, 10.234077, 1013.88629, 53.387184],
        bending: [64.196457e-6, 73.384567e-6, 96.951576e-6],
    },
];

/// What `material.preset` allows, for error messages.
pub(crate) const ALLOWED: &str = "one of \"tango-red-jet-set\", \"white-dots-on-blk\", \
\"gray-interlock\", \"white-swim-solid\", \"royal-target\", \"navy-sparkle-sweat\", \
\"pink-ribbon-brown\", \"ivory-rib-knit\", \"camel-ponte-roma\", \"11oz-black-denim\" \
(docs/fabrics.md)";

/// The fabric called `name`, if there is one.
pub fn find(name: &str) -> Option<&'static Fabric> {
    FABRICS.iter().find(|f| f.name == name)
}

/// `doc` with the values of `material.preset` written into `[material]` where
/// the table does not give the key itself: `density`, `membrane`
/// (`"triangles"`), `stretch`, `warp`, `weft` and `shear` (not with a written
/// `stretch`, the isotropic shorthand, nor with `membrane = "springs"`), and
/// `bending` (not with a written `bending_length`). A `preset` that is not a
/// string is left for deserialisation to report.
pub(super) fn expand(mut doc: Table) -> Result<Table, Issue> {
    let Some(Value::Table(m)) = doc.get_mut("material") else {
        return Ok(doc);
    };
    let Some(Value::String(name)) = m.get("preset") else {
        return Ok(doc);
    };
    let Some(f) = find(name) else {
        return Err(Issue::new(
            keys(&["material", "preset"]),
            Kind::BadValue,
            format!("no fabric preset is called \"{name}\""),
        )
        .allowed(ALLOWED));
    };
    let springs = m.get("membrane").and_then(Value::as_str) == Some("springs");
    let moduli = !springs && !m.contains_key("stretch");
    let bending = !m.contains_key("bending_length");
    let mut fill = |key: &str, value: Value| {
        m.entry(key).or_insert(value);
    };
    fill("density", Value::Float(f.density));
    fill("membrane", Value::String("triangles".into()));
    fill("stretch", Value::Float(f.stretch()));
    if moduli {
        fill("warp", Value::Float(f.warp()));
        fill("weft", Value::Float(f.weft()));
        fill("shear", Value::Float(f.shear()));
    }
    if bending {
        fill("bending", Value::Float(f.rigidity()));
    }
    Ok(doc)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn allowed_names_every_fabric_once() {
        for f in &FABRICS {
            assert_eq!(
                ALLOWED.matches(&format!("\"{}\"", f.name)).count(),
                1,
                "{}",
                f.name
            );
        }
        assert_eq!(ALLOWED.matches('"').count(), 2 * FABRICS.len());
    }

    #[test]
    fn every_fabric_has_positive_moduli() {
        for f in &FABRICS {
            let all = [f.density, f.warp(), f.weft(), f.shear(), f.rigidity()];
            assert!(all.iter().all(|&x| x > 0.0), "{}: {all:?}", f.name);
        }
    }
}
