//! Which way each panel faces. GarmentCode faces a panel the way its outline
//! winds, but its stitches join panels whichever way they face: a stitch
//! `"right_wrong"` (a collar turned over onto the bodice) joins a panel's
//! front to another's back. A weld needs every seam to join two panels
//! facing one way across it, so drape turns some panels over where
//! GarmentCode's facings would twist a seam.

use std::collections::HashMap;

use crate::spec::{SeamDirection, SeamSpec};

/// Which panels to turn over (face the other way than GarmentCode faces them,
/// each point kept where it is) so that no seam is twisted: a seam
/// `Opposite` joins two panels facing as GarmentCode faces them, or both
/// turned over; a seam `Same` joins one turned over to one not. In each group
/// of panels the seams connect, the fewer panels are turned (the first panel
/// of the group, in `names`' order, is not, on a tie); a group whose seams
/// cannot all be untwisted is left as GarmentCode faces it (the garment's
/// build then names the twisted seam). `names` are the panels in order;
/// a seam naming no panel of them is left out.
pub fn turned_over(names: &[String], seams: &[SeamSpec]) -> Vec<bool> {
    let index: HashMap<&str, usize> = names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.as_str(), i))
        .collect();
    // links[p]: (q, flip): q is turned iff p is, XOR flip.
    let mut links: Vec<Vec<(usize, bool)>> = vec![Vec::new(); names.len()];
    for s in seams {
        let flip = s.direction == SeamDirection::Same;
        for (a, b) in s.a.iter().flat_map(|a| s.b.iter().map(move |b| (a, b))) {
            let (Some(&a), Some(&b)) = (index.get(a.panel.as_str()), index.get(b.panel.as_str()))
            else {
                continue;
            };
            links[a].push((b, flip));
            links[b].push((a, flip));
        }
    }
    let mut turned = vec![false; names.len()];
    let mut seen = vec![false; names.len()];
    for root in 0..names.len() {
        if seen[root] {
            continue;
        }
        let (group, consistent) = colour_group(root, &links, &mut turned, &mut seen);
        let count = group.iter().filter(|&&p| turned[p]).count();
        for &p in &group {
            // Left as GarmentCode faces it, or the colouring with fewer turned.
            turned[p] = consistent && (turned[p] != (2 * count > group.len()));
        }
    }
    turned
}

/// Colours the group of panels connected to `root`, `root` not turned; returns
/// the group and whether every seam in it agrees with the colouring.
fn colour_group(
    root: usize,
    links: &[Vec<(usize, bool)>],
    turned: &mut [bool],
    seen: &mut [bool],
) -> (Vec<usize>, bool) {
    seen[root] = true;
    turned[root] = false;
    let mut group = vec![root];
    let mut stack = vec![root];
    let mut consistent = true;
    while let Some(p) = stack.pop() {
        for &(q, flip) in &links[p] {
            let want = turned[p] != flip;
            if !seen[q] {
                seen[q] = true;
                turned[q] = want;
                group.push(q);
                stack.push(q);
            } else if turned[q] != want {
                consistent = false;
            }
        }
    }
    (group, consistent)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::{Gather, SeamSide};

    fn seam(a: &str, b: &str, direction: SeamDirection) -> SeamSpec {
        let side = |panel: &str| SeamSide {
            panel: panel.into(),
            side: 1,
        };
        SeamSpec {
            name: format!("{a}-{b}"),
            a: vec![side(a)],
            b: vec![side(b)],
            direction,
            gather: Gather::None,
        }
    }

    fn names(n: &[&str]) -> Vec<String> {
        n.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn a_collar_sewn_right_to_wrong_on_both_bodice_panels_is_turned_over() {
        use SeamDirection::{Opposite, Same};
        let panels = names(&["front", "back", "collar_front", "collar_back"]);
        let seams = [
            seam("front", "back", Opposite),
            seam("front", "collar_front", Same),
            seam("collar_front", "collar_back", Opposite),
            seam("back", "collar_back", Same),
        ];
        assert_eq!(turned_over(&panels, &seams), [false, false, true, true]);
    }

    #[test]
    fn the_fewer_panels_of_a_group_are_turned_and_a_twisted_cycle_turns_none() {
        use SeamDirection::{Opposite, Same};
        let panels = names(&["collar", "front", "back", "a", "b", "c"]);
        let seams = [
            seam("collar", "front", Same),
            seam("front", "back", Opposite),
            // a, b, c: a cycle with one Same seam cannot be untwisted.
            seam("a", "b", Opposite),
            seam("b", "c", Opposite),
            seam("c", "a", Same),
        ];
        assert_eq!(
            turned_over(&panels, &seams),
            [true, false, false, false, false, false]
        );
    }
}
