//! What each key allows, in words, for error messages (mirrors `docs/scenes.md`).

/// The allowed values of the key at `path` (`pin.0.region` is looked up as
/// `pin.region`), or `None` for paths that are not keys of the format. Long because
/// it is the table of every key, kept in one place like `docs/scenes.md`.
pub(crate) fn allowed(path: &str) -> Option<&'static str> {
    let key: Vec<&str> = path
        .split('.')
        .filter(|p| p.parse::<usize>().is_err())
        .collect();
    Some(match key.join(".").as_str() {
        "name" => "a non-empty string without `/` or `\\`",
        "measure" => "an array of measurements: \"cantilever\", \"cusick\"",
        "simulation" => "a table [simulation]",
        "simulation.duration" => "a finite number > 0 (s)",
        "simulation.frame_rate" => "a finite number > 0 (frames per second)",
        "simulation.integrator" => "\"symplectic_euler\", \"rk4\" or \"implicit\"",
        "simulation.dt" => {
            "\"auto\", \"adaptive\" (implicit integrator) or a finite number of seconds > 0 and <= 1/frame_rate"
        }
        "simulation.adaptive_dt" => {
            "a table [simulation.adaptive_dt] (used with dt = \"adaptive\")"
        }
        "simulation.adaptive_dt.tolerance" => "a finite number > 0 (m)",
        "simulation.adaptive_dt.penetration" => "a finite number > 0 (m)",
        "simulation.adaptive_dt.min" => "a finite number of seconds > 0 and <= 1/frame_rate",
        "simulation.adaptive_dt.max" => "a finite number of seconds >= min",
        "simulation.gravity" => "an array of 3 finite numbers (m/s^2)",
        "simulation.cg_tolerance" => "a number in the open interval (0, 1)",
        "simulation.cg_max_iterations" => "an integer >= 1",
        "simulation.solver" => "\"direct\", \"cg\" or \"quasi_newton\"",
        "simulation.refactor_iterations" => "an integer >= 1",
        "simulation.refactor" => "\"cost\", \"every_solve\" or \"per_mesh\"",
        "simulation.preconditioner" => "\"factor\", \"factor_single\" or \"laplacian\"",
        "simulation.bending_matrix" => "\"first_ring\" or \"exact\"",
        "simulation.newton_iterations" => "an integer from 1 to 100",
        "simulation.newton_tolerance" => "a number in the open interval (0, 1)",
        "simulation.quasi_newton_iterations" => "an integer from 1 to 100000",
        "cloth" => "a table [cloth]",
        "cloth.shape" => "\"rectangle\", \"disk\", \"obj\" or \"panels\"",
        "cloth.max_edge" => "a finite number > 0 (m; panels only)",
        "cloth.width" | "cloth.height" | "cloth.radius" => "a finite number > 0 (m)",
        "cloth.resolution" => "an integer from 1 to 2048 (segments)",
        "cloth.short_side_segments" => "an integer from 1 to 2048 (segments; rectangle only)",
        "cloth.diagonals" => "\"alternating\", \"alternating_flipped\" or \"regular\"",
        "cloth.path" => "a non-empty path to an OBJ file, relative to the scene file",
        "cloth.uv_scale" => "a finite number > 0 (m per texture-coordinate unit)",
        "cloth.position" => "an array of 3 finite numbers (m)",
        "cloth.rotation" => "an array of 3 finite numbers (degrees)",
        "panel" => "an array of tables [[panel]] (with cloth.shape = \"panels\")",
        "panel.name" => "a non-empty string, unique among the panels",
        "panel.outline" => "an array of at least 3 [u, v] corners (m), finite, a simple polygon",
        "panel.position" => "an array of 3 finite numbers (m)",
        "panel.rotation" => "an array of 3 finite numbers (degrees); not with `wrap`",
        "panel.wrap" => "a table { radius, angle } (m, degrees), radius > 0",
        "panel.wrap.radius" => "a finite number > 0 (m)",
        "panel.wrap.angle" => "a finite number (degrees)",
        "panel.curves" => {
            "an array of { side, kind, controls } (kind \"quadratic\" or \"cubic\") or \
             { side, kind = \"arc\", radius, large_arc, counter_clockwise }, one per side"
        }
        "seam" => "an array of tables [[seam]] (with cloth.shape = \"panels\")",
        "seam.name" => "a non-empty string, unique among the seams",
        "seam.a" | "seam.b" => {
            "a table { panel, side } (an existing panel and a side 1 to its corner count), \
             or a non-empty array of such tables joined end to end"
        }
        "seam.a.panel" | "seam.b.panel" => "the name of a [[panel]]",
        "seam.a.side" | "seam.b.side" => "an integer from 1 to the panel's corner count",
        "seam.direction" => "\"opposite\" or \"same\"",
        "seam.gather" => "true or false",
        "attachment" => "an array of tables [[attachment]] (with cloth.shape = \"panels\")",
        "attachment.name" => "a non-empty string, unique among the attachments",
        "attachment.sides" => {
            "a non-empty array of tables { panel, side }: an existing panel and a side 1 to \
             its corner count"
        }
        "attachment.sides.panel" => "the name of a [[panel]]",
        "attachment.sides.side" => "an integer from 1 to the panel's corner count",
        "attachment.point" => "an array of 3 finite numbers (m, world)",
        "attachment.normal" => "an array of 3 finite numbers, not all 0 (world)",
        "attachment.stiffness" => "a finite number > 0 (N/m per m of held side)",
        "attachment.release" => "a finite number >= 0 (s); absent: never released",
        "cloth.sewing" => "a table [cloth.sewing] (shape = \"panels\" or \"obj\" only)",
        "cloth.sewing.stiffness" => "a finite number > 0 (N/m per m of seam)",
        "cloth.sewing.weld_gap" => "a finite number > 0 (m)",
        "cloth.sewing.max_force" => "a finite number > 0 (N per m of seam); absent: no cap",
        "cloth.sewing.weightless" => "a finite number > 0 (s); absent: gravity from the start",
        "simulation.rest" => "a table { speed, window } (m/s, s), both > 0",
        "simulation.rest.speed" => "a finite number > 0 (m/s)",
        "simulation.rest.window" => "a finite number > 0 (s)",
        "material" => "a table [material]",
        "material.preset" => super::presets::ALLOWED,
        "material.density" => "a finite number > 0 (kg/m^2)",
        "material.stretch" => "a finite number > 0 (N/m)",
        "material.membrane" => "\"springs\" or \"triangles\"",
        "material.warp" | "material.weft" | "material.shear" => {
            "a finite number > 0 (N/m), with membrane = \"triangles\""
        }
        "material.bending" => "a finite number >= 0 (N m)",
        "material.bending_length" => {
            "a finite number > 0 (m), instead of `bending` (not both); needs non-zero gravity"
        }
        "material.damping" => "a finite number >= 0 (s)",
        "material.bending_model" => "\"shape_operator\", \"dihedral\" or \"hinge_spring\"",
        "material.stiffness_rule" => "\"consistent\" or \"paper_a\"",
        "pin" => "an array of tables [[pin]]",
        "pin.region" => REGIONS,
        "pin.box_min" | "pin.box_max" => {
            "an array of 2 finite numbers (material coordinates, m), box_min < box_max"
        }
        "pin.disk_center" => "an array of 2 finite numbers (material coordinates, m)",
        "pin.disk_radius" => "a finite number > 0 (m)",
        "pin.motion" => "\"fixed\", \"linear\", \"circular\" or \"keyframed\" (not with `attach`)",
        "pin.attach" => {
            "the `name` of an [[obstacle]] that is not a mesh_sequence (\"NAME\"), or \"NAME/PART\" for a part of an articulated one"
        }
        "pin.velocity" => "an array of 3 finite numbers (m/s)",
        "pin.acceleration" => "an array of 3 finite numbers (m/s^2)",
        "pin.center" => "an array of 3 finite numbers (m)",
        "pin.axis" => "an array of 3 finite numbers, not all zero",
        "pin.angular_velocity" => "a finite number (rad/s)",
        "pin.keyframes" => {
            "an array of at least two tables {time, translation, rotation} with increasing times (motion = \"keyframed\")"
        }
        "pin.keyframes.time" => "a finite number (s), larger than the key before's",
        "pin.keyframes.translation" => "an array of 3 finite numbers (m)",
        "pin.keyframes.rotation" => "an array of 3 finite numbers (degrees)",
        "pin.easing" => "\"linear\" or \"smooth\"",
        "pin.after_last" => "\"hold\" or \"loop\"",
        "pin.release_time" => "a finite number >= 0 (s)",
        "air" => "a table [air]",
        "air.drag" => "a finite number >= 0 (kg/(m^2 s))",
        "air.density" => "a finite number > 0 (kg/m^3)",
        "wind" => "a table [wind]",
        "wind.velocity" => "an array of 3 finite numbers (m/s)",
        "wind.coefficient" => "a finite number >= 0",
        "obstacle" => "an array of tables [[obstacle]]",
        "obstacle.name" => "a non-empty string without `/`, unique among the obstacles",
        "obstacle.shape" => {
            "\"sphere\", \"box\", \"plane\", \"capsule\", \"cylinder\", \"mesh\", \"mesh_sequence\" or \"articulated\""
        }
        "obstacle.radius" | "obstacle.half_height" => "a finite number > 0 (m)",
        "obstacle.half_extents" => "an array of 3 finite numbers > 0 (m)",
        "obstacle.normal" => "an array of 3 finite numbers, not all zero",
        "obstacle.path" => "a non-empty path to an OBJ file, relative to the scene file",
        "obstacle.scale" => "a finite number > 0",
        "obstacle.files" => {
            "a path pattern with one `{}` or `{:0N}` placeholder for the frame number, or a non-empty array of paths to OBJ files (relative to the scene file)"
        }
        "obstacle.frame_rate" => "a finite number > 0 (frames per second)",
        "obstacle.first_frame" => "an integer >= 0 (with a `files` pattern)",
        "obstacle.surface" => "\"parts\" or \"skinned_mesh\" (shape = \"articulated\" only)",
        "obstacle.position" => "an array of 3 finite numbers (m)",
        "obstacle.rotation" => "an array of 3 finite numbers (degrees)",
        "obstacle.friction_static" => "a finite number >= 0",
        "obstacle.friction_kinetic" => "a finite number >= 0 and <= friction_static",
        "obstacle.thickness" => "a finite number > 0 (m)",
        "obstacle.velocity" => "an array of 3 finite numbers (m/s)",
        "obstacle.angular_velocity" => "a finite number (rad/s)",
        "obstacle.axis" => "an array of 3 finite numbers, not all zero",
        "obstacle.keyframes" => {
            "an array of at least two tables {time, translation, rotation} with increasing times"
        }
        "obstacle.keyframes.time" => "a finite number (s), larger than the key before's",
        "obstacle.keyframes.translation" => "an array of 3 finite numbers (m)",
        "obstacle.keyframes.rotation" => "an array of 3 finite numbers (degrees)",
        "obstacle.easing" => "\"linear\" or \"smooth\"",
        "obstacle.after_last" => {
            "\"hold\" or \"loop\" (with keyframes or shape = \"mesh_sequence\")"
        }
        "obstacle.part" => {
            "an array of at least one table [[obstacle.part]] (shape = \"articulated\" only)"
        }
        "obstacle.part.name" => "a non-empty string, unique among the obstacle's parts",
        "obstacle.part.parent" => "the name of another part of the same obstacle",
        "obstacle.part.shape" => "\"sphere\", \"capsule\" or \"box\"",
        "obstacle.part.radius" | "obstacle.part.half_height" => "a finite number > 0 (m)",
        "obstacle.part.half_extents" => "an array of 3 finite numbers > 0 (m)",
        "obstacle.part.joint" | "obstacle.part.center" => "an array of 3 finite numbers (m)",
        "obstacle.part.rotation" => "an array of 3 finite numbers (degrees)",
        "obstacle.part.keyframes" => {
            "an array of at least two tables {time, rotation} with increasing times"
        }
        "obstacle.part.keyframes.time" => "a finite number (s), larger than the key before's",
        "obstacle.part.keyframes.translation" => "none: a joint only turns",
        "obstacle.part.keyframes.rotation" => "an array of 3 finite numbers (degrees)",
        "obstacle.part.easing" => "\"linear\" or \"smooth\"",
        "obstacle.part.after_last" => "\"hold\" or \"loop\"",
        "camera" => "a table [camera]",
        "camera.side" => "\"front\", \"back\", \"left\", \"right\" or \"top\"",
        "camera.eye" => "an array of 3 finite numbers (m), with camera.look_at",
        "camera.look_at" => "an array of 3 finite numbers (m), other than camera.eye",
        "self_collision" => "a table [self_collision]",
        "self_collision.thickness" => "a finite number > 0 (m)",
        "self_collision.iterations" => "an integer >= 1",
        "self_collision.culling" => "true or false",
        "self_collision.patch_size" => "a finite number > 0 (m, material space)",
        "adapt" => "a table [adapt]",
        "adapt.method" => "\"red_green\", \"edge\", \"tensor\" (rectangles only) or \"none\"",
        "adapt.refine_angle" => "a finite number of degrees in (coarsen_angle, 180)",
        "adapt.coarsen_angle" => "a finite number of degrees in (0, refine_angle)",
        "adapt.max_level" => "an integer >= 1 (at most 254; even with method = \"tensor\")",
        "adapt.min_edge_length" => "a finite number >= 0 (m, material space; 0: no limit)",
        "adapt.every" => "an integer >= 1 (steps) or \"frame\"",
        "adapt.min_change" => {
            "a finite number in [0, 1] (a fraction of the triangles; 0: off; method = \"red_green\" only)"
        }
        "adapt.urgent_ratio" => "a finite number >= 1 (a ratio of the criterion; with min_change)",
        "adapt.rollback" => "true or false",
        "adapt.max_rollbacks" => "an integer >= 0",
        "adapt.multirate" => "true or false (explicit integrators only)",
        "adapt.criterion" => "\"angle\" or \"sizing\"",
        "adapt.hysteresis" => "a finite number > 1 (criterion = \"sizing\" only)",
        "adapt.diagonals" => "\"alternating\" or \"as_split\" (method = \"red_green\" only)",
        "adapt.refine_strain" => {
            "a finite number > 0 (criterion = \"sizing\" with method = \"red_green\" only)"
        }
        "adapt.refine_obstacle" => {
            "a finite number > 0 (criterion = \"sizing\" with method = \"red_green\" only, in a scene with an [[obstacle]])"
        }
        _ => return None,
    })
}

/// The pin region syntax.
pub(crate) const REGIONS: &str = "\"corner:top_left\", \"corner:top_right\", \
\"corner:bottom_left\", \"corner:bottom_right\", \"edge:top\", \"edge:bottom\", \
\"edge:left\", \"edge:right\", \"box\" (with box_min and box_max), \"disk\" (with disk_radius) \
or \"all\"";
