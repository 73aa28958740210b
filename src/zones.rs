//! Struck zones: the colliding area as a designer reads it, a list of
//! connected places rather than a mask of nodes (issue 43, item 1).
//!
//! A **zone** is a connected set of the composite's colliding nodes, nodes
//! joined when they are 8-neighbours on the grid (a diagonal step joins: a
//! strike along a slanted crease is one zone, not a staircase of specks).
//! Each node stands for its cell of `p x p` mm around it, so a zone's area
//! is its node count times `p^2`, as the summary's colliding area is.
//!
//! Per zone: the angles whose own mask strikes one of its nodes, written as
//! runs over the analysed angles ("-30 to -12, 4 to 30"), the largest
//! composite count among its nodes, its bounding box and centroid in the
//! part's own coordinates (the nodes' surface points `(x, h, z)` mapped back
//! by the run's [`Placement`]), and whether a blind spot's cell touches it
//! (shares or neighbours one of its nodes). A zone of fewer than
//! [`SPECK_NODES`] nodes is a **speck**: listed, never hidden, with the
//! nearest zone that is not one (its neighbour), so a reader sees a stray
//! node beside the area it belongs to rather than as a place of its own.
//!
//! A verification of the same part and grid says where the grid's boundary
//! is undecided (`verify.json`'s `undecided_nodes`, a [`NodeRuns`]): a
//! zone is **touched** by it when one of its nodes is on or 8-adjacent to
//! an undecided node ([`touched_by`]), as the report's zone table says.
//!
//! **Invariant:** zones partition the composite's colliding nodes; their
//! ids follow their order, largest area first (ties: the smaller first node
//! index, row-major), so the same mask gives the same ids on every run.

use crate::blind::BlindSpot;
use crate::engine::AngleMask;
use crate::frame::Placement;
use crate::grid::HeightGrid;

/// Below this many nodes a zone is a speck (listed beside its neighbour):
/// fewer than a 2 x 2 patch of cells is below what a pitch resolves.
pub const SPECK_NODES: usize = 4;

/// One connected colliding zone of the composite.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Zone {
    /// 1 for the largest zone, then by decreasing area.
    pub id: usize,
    /// Its colliding nodes.
    pub nodes: usize,
    /// Its area (mm^2): `nodes x p^2`.
    pub area_mm2: f64,
    /// The smallest corner of its nodes' surface points, in the part's own
    /// coordinates (mm).
    pub bbox_min: [f64; 3],
    /// The largest corner (mm).
    pub bbox_max: [f64; 3],
    /// The mean of its nodes' surface points, in the part's own
    /// coordinates (mm).
    pub centroid: [f64; 3],
    /// The analysed angles (degrees) whose mask strikes one of its nodes,
    /// ascending.
    pub angles_deg: Vec<f64>,
    /// The same angles as runs of consecutive analysed angles, e.g.
    /// `-30 to -12, 4 to 30`.
    pub angle_runs: String,
    /// The largest number of angles striking one of its nodes.
    pub max_count: u16,
    /// Whether a blind spot's cell shares or neighbours one of its nodes.
    pub touches_blind_spot: bool,
    /// Fewer than [`SPECK_NODES`] nodes.
    pub speck: bool,
    /// For a speck, the id of the nearest zone that is not a speck (by
    /// the distance between their closest nodes); `None` otherwise, or
    /// when every zone is a speck.
    pub beside: Option<usize>,
}

/// The zones of a composite: connected (8-neighbour) sets of its colliding
/// nodes, described as [`Zone`] says, largest first.
///
/// `masks` are the per-angle masks the composite counts (an empty mask, an
/// angle outside a shard, strikes nothing); `angles_deg` the analysed
/// angles in the order of the run.
pub fn zones(
    grid: &HeightGrid,
    composite: &[u16],
    masks: &[AngleMask],
    blind_spots: &[BlindSpot],
    placement: &Placement,
) -> Vec<Zone> {
    let spec = grid.spec;
    let (nx, nz) = (spec.nx, spec.nz);
    let members = components(composite, nx, nz);
    let mut analysed: Vec<f64> = masks.iter().map(|m| m.angle_deg).collect();
    analysed.sort_by(f64::total_cmp);
    analysed.dedup();
    let area = spec.pitch * spec.pitch;
    let mut out: Vec<Zone> = members
        .iter()
        .enumerate()
        .map(|(k, nodes)| {
            let (mut lo, mut hi, mut sum) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3], [0.0; 3]);
            for &n in nodes {
                let p = placement.to_part([spec.x(n % nx), grid.h[n], spec.z(n / nx)]);
                for c in 0..3 {
                    lo[c] = lo[c].min(p[c]);
                    hi[c] = hi[c].max(p[c]);
                    sum[c] += p[c];
                }
            }
            let mut angles_deg: Vec<f64> = masks
                .iter()
                .filter(|m| !m.mask.is_empty() && nodes.iter().any(|&n| m.mask[n] != 0))
                .map(|m| m.angle_deg)
                .collect();
            angles_deg.sort_by(f64::total_cmp);
            angles_deg.dedup();
            let touches_blind_spot = blind_spots.iter().any(|s| {
                nodes.iter().any(|&n| {
                    let (i, j) = (n % nx, n / nx);
                    // The cell spans columns s.i..=s.i+1 and rows s.j..=s.j+1;
                    // a node touches it when within one node of those.
                    i + 1 >= s.i && i <= s.i + 2 && j + 1 >= s.j && j <= s.j + 2
                })
            });
            Zone {
                id: k + 1,
                nodes: nodes.len(),
                area_mm2: nodes.len() as f64 * area,
                bbox_min: lo,
                bbox_max: hi,
                centroid: sum.map(|s| s / nodes.len() as f64),
                angle_runs: angle_runs(&angles_deg, &analysed),
                angles_deg,
                max_count: nodes.iter().map(|&n| composite[n]).max().unwrap_or(0),
                touches_blind_spot,
                speck: nodes.len() < SPECK_NODES,
                beside: None,
            }
        })
        .collect();
    for k in 0..out.len() {
        if out[k].speck {
            out[k].beside = nearest_zone(&members, &out, k, nx);
        }
    }
    out
}

/// A set of grid nodes written compactly: runs of adjacent nodes along a
/// row, in the lattice's own indices (node column `c` at `x = c p`, row
/// `r` at `z = r p`, mm, analysis frame), so that the set reads the same
/// on any grid of the same pitch whatever its origin. `verify.json` holds
/// its undecided nodes this way.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct NodeRuns {
    /// The pitch `p` of the grid whose nodes these are (mm).
    pub pitch_mm: f64,
    /// How many nodes the runs hold.
    pub nodes: usize,
    /// `[row, first column, last column]` (lattice indices, both columns
    /// included), ascending by row then column, never overlapping or
    /// adjacent.
    pub runs: Vec<[i64; 3]>,
}

impl NodeRuns {
    /// The nodes `(i, j)` of the grid `spec` (each once, in any order) as
    /// runs.
    pub fn of(nodes: &[(usize, usize)], spec: &crate::grid::GridSpec) -> NodeRuns {
        let mut lattice: Vec<(i64, i64)> = nodes
            .iter()
            .map(|&(i, j)| (spec.j_origin + j as i64, spec.i_origin + i as i64))
            .collect();
        lattice.sort_unstable();
        lattice.dedup();
        let mut runs: Vec<[i64; 3]> = Vec::new();
        for &(row, column) in &lattice {
            match runs.last_mut() {
                Some(run) if run[0] == row && run[2] + 1 == column => run[2] = column,
                _ => runs.push([row, column, column]),
            }
        }
        NodeRuns {
            pitch_mm: spec.pitch,
            nodes: lattice.len(),
            runs,
        }
    }

    /// Their area (mm^2): each node stands for its cell of `p x p`, as a
    /// zone's does; rounded to 1e-6 mm^2, so that it prints as its decimal.
    pub fn area_mm2(&self) -> f64 {
        (self.nodes as f64 * self.pitch_mm * self.pitch_mm * 1e6).round() / 1e6
    }

    /// Every node as `(column, row)` lattice indices, row-major.
    pub fn lattice_nodes(&self) -> impl Iterator<Item = (i64, i64)> + '_ {
        self.runs
            .iter()
            .flat_map(|&[row, first, last]| (first..=last).map(move |c| (c, row)))
    }

    /// On the grid `spec` (of the same pitch), per node (row-major by z)
    /// whether it is one of these; `None` when the pitches differ (the
    /// sets are of different grids). Nodes off `spec` are left out.
    pub fn mask_on(&self, spec: &crate::grid::GridSpec) -> Option<Vec<bool>> {
        let same = (self.pitch_mm - spec.pitch).abs() <= 1e-9 * spec.pitch;
        if !same {
            return None;
        }
        let mut mask = vec![false; spec.len()];
        for (c, r) in self.lattice_nodes() {
            let (i, j) = (c - spec.i_origin, r - spec.j_origin);
            if (0..spec.nx as i64).contains(&i) && (0..spec.nz as i64).contains(&j) {
                mask[j as usize * spec.nx + i as usize] = true;
            }
        }
        Some(mask)
    }
}

/// For each zone (`members`, as [`components`] gives them, on an
/// `nx x nz` grid), whether one of its nodes is on or 8-adjacent to a
/// node marked in `marked` (row-major by z): an undecided boundary
/// touches it.
pub fn touched_by(members: &[Vec<usize>], nx: usize, nz: usize, marked: &[bool]) -> Vec<bool> {
    let near = |n: usize| {
        let (i, j) = ((n % nx) as isize, (n / nx) as isize);
        std::iter::once((0, 0)).chain(NEIGHBOURS).any(|(di, dj)| {
            let (a, b) = (i + di, j + dj);
            a >= 0
                && b >= 0
                && a < nx as isize
                && b < nz as isize
                && marked.get(b as usize * nx + a as usize) == Some(&true)
        })
    };
    members
        .iter()
        .map(|nodes| nodes.iter().any(|&n| near(n)))
        .collect()
}

/// The 8-connected components of the nodes of an `nx x nz` grid
/// (row-major by z) with a non-zero count, each as its nodes' indices in
/// ascending order, largest first (equal sizes by their first node): the
/// zones' order, whose ids are their positions plus one.
pub fn components(counts: &[u16], nx: usize, nz: usize) -> Vec<Vec<usize>> {
    let labels = label(counts, nx, nz);
    let count = labels.iter().flatten().map(|&l| l + 1).max().unwrap_or(0);
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); count];
    for (n, l) in labels.iter().enumerate() {
        if let Some(l) = *l {
            members[l].push(n);
        }
    }
    members.sort_by(|a, b| b.len().cmp(&a.len()).then(a[0].cmp(&b[0])));
    members
}

/// The 8-connected components of the nodes with a non-zero count: per
/// node its component's index, numbered in the order of their first node
/// (row-major), or `None` off the area.
fn label(composite: &[u16], nx: usize, nz: usize) -> Vec<Option<usize>> {
    let mut labels: Vec<Option<usize>> = vec![None; composite.len()];
    let mut next = 0;
    let mut stack = Vec::new();
    for start in 0..composite.len() {
        if composite[start] == 0 || labels[start].is_some() {
            continue;
        }
        labels[start] = Some(next);
        stack.push(start);
        while let Some(n) = stack.pop() {
            let (i, j) = ((n % nx) as isize, (n / nx) as isize);
            for (di, dj) in NEIGHBOURS {
                let (a, b) = (i + di, j + dj);
                if a < 0 || b < 0 || a >= nx as isize || b >= nz as isize {
                    continue;
                }
                let m = b as usize * nx + a as usize;
                if composite[m] != 0 && labels[m].is_none() {
                    labels[m] = Some(next);
                    stack.push(m);
                }
            }
        }
        next += 1;
    }
    labels
}

/// The eight neighbours of a node, as (column, row) steps.
const NEIGHBOURS: [(isize, isize); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// The id of the zone that is not a speck nearest to zone `k` (the
/// smallest node-to-node distance, in nodes; ties to the smaller id).
fn nearest_zone(members: &[Vec<usize>], zones: &[Zone], k: usize, nx: usize) -> Option<usize> {
    let at = |n: usize| ((n % nx) as f64, (n / nx) as f64);
    zones
        .iter()
        .enumerate()
        .filter(|(other, z)| *other != k && !z.speck)
        .map(|(other, z)| {
            let d = members[k]
                .iter()
                .flat_map(|&a| members[other].iter().map(move |&b| (a, b)))
                .map(|(a, b)| {
                    let ((xa, za), (xb, zb)) = (at(a), at(b));
                    (xa - xb).hypot(za - zb)
                })
                .fold(f64::INFINITY, f64::min);
            (d, z.id)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        .map(|(_, id)| id)
}

/// `angles` (ascending, a subset of `analysed`, which is ascending) as runs
/// of consecutive analysed angles: "-30 to -12, 4 to 30"; a run of one
/// angle is that angle alone; "none" when empty.
pub fn angle_runs(angles: &[f64], analysed: &[f64]) -> String {
    if angles.is_empty() {
        return "none".into();
    }
    let struck: Vec<bool> = analysed
        .iter()
        .map(|a| angles.iter().any(|b| b == a))
        .collect();
    let mut runs: Vec<String> = Vec::new();
    let mut k = 0;
    while k < analysed.len() {
        if !struck[k] {
            k += 1;
            continue;
        }
        let first = k;
        while k + 1 < analysed.len() && struck[k + 1] {
            k += 1;
        }
        runs.push(if first == k {
            format!("{}", analysed[first])
        } else {
            format!("{} to {}", analysed[first], analysed[k])
        });
        k += 1;
    }
    runs.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Side;
    use crate::grid::GridSpec;

    fn placement() -> Placement {
        Placement::from(Side::Left)
    }

    /// A 6 x 4 grid at 2 mm, flat at y = 10.
    fn grid() -> HeightGrid {
        let spec = GridSpec::explicit(0.0, 0.0, 6, 4, 2.0);
        HeightGrid::from_fn(spec, |_, _| 10.0)
    }

    fn mask(angle_deg: f64, on: &[usize], len: usize) -> AngleMask {
        let mut mask = vec![0; len];
        for &n in on {
            mask[n] = 1;
        }
        AngleMask {
            angle_deg,
            mask,
            placed: 1,
            colliding: on.len(),
            probes_met: Vec::new(),
        }
    }

    #[test]
    fn runs_of_consecutive_analysed_angles() {
        let analysed: Vec<f64> = (-30..=30).map(f64::from).collect();
        let mut angles: Vec<f64> = (-30..=-12).map(f64::from).collect();
        angles.extend((4..=30).map(f64::from));
        assert_eq!(angle_runs(&angles, &analysed), "-30 to -12, 4 to 30");
        assert_eq!(angle_runs(&[0.0], &analysed), "0");
        assert_eq!(angle_runs(&[], &analysed), "none");
        // Consecutive in the analysed list, not in whole degrees.
        assert_eq!(angle_runs(&[-30.0, 0.0], &[-30.0, 0.0, 30.0]), "-30 to 0");
    }

    #[test]
    fn diagonal_neighbours_join_and_specks_stand_beside_their_neighbour() {
        let g = grid();
        let len = g.spec.len();
        // Row-major, nx = 6: a 2 x 2 block at columns 0-1 of rows 0-1,
        // joined diagonally by node (2, 2); a lone node at (5, 0).
        let block = [0, 1, 6, 7, 14];
        let masks = [mask(-30.0, &block, len), mask(0.0, &[0, 5], len)];
        let mut composite = vec![0u16; len];
        for m in &masks {
            for (c, &v) in composite.iter_mut().zip(&m.mask) {
                *c += u16::from(v);
            }
        }
        let z = zones(&g, &composite, &masks, &[], &placement());
        assert_eq!(z.len(), 2);
        assert_eq!((z[0].id, z[0].nodes, z[0].area_mm2), (1, 5, 20.0));
        assert_eq!(z[0].angles_deg, vec![-30.0, 0.0]);
        assert_eq!(z[0].angle_runs, "-30 to 0");
        assert_eq!(z[0].max_count, 2);
        assert!(!z[0].speck);
        assert_eq!(z[0].bbox_min, [0.0, 10.0, 0.0]);
        assert_eq!(z[0].bbox_max, [4.0, 10.0, 4.0]);
        assert_eq!(z[0].centroid, [1.6, 10.0, 1.6]);
        assert_eq!((z[1].nodes, z[1].speck, z[1].beside), (1, true, Some(1)));
        assert_eq!(z[1].angle_runs, "0");
        // The zones partition the colliding nodes.
        let colliding = composite.iter().filter(|&&c| c > 0).count();
        assert_eq!(z.iter().map(|z| z.nodes).sum::<usize>(), colliding);
    }

    #[test]
    fn a_blind_spot_beside_a_zone_touches_it_and_one_far_away_does_not() {
        let g = grid();
        let len = g.spec.len();
        let masks = [mask(0.0, &[0, 1, 6, 7], len)];
        let composite: Vec<u16> = masks[0].mask.iter().map(|&v| u16::from(v)).collect();
        let spot = |i, j| BlindSpot {
            i,
            j,
            x: 0.0,
            z: 0.0,
            depth_missed_mm: 1.0,
            width_mm: 1.0,
            resolving_pitch_mm: 1.0,
            y: 0.0,
            met_angles_deg: Vec::new(),
        };
        let near = zones(&g, &composite, &masks, &[spot(2, 1)], &placement());
        assert!(near[0].touches_blind_spot);
        let far = zones(&g, &composite, &masks, &[spot(4, 2)], &placement());
        assert!(!far[0].touches_blind_spot);
    }

    #[test]
    fn node_runs_join_adjacent_columns_and_read_back_on_a_shifted_grid() {
        // A 6 x 4 grid at 2 mm whose node (0, 0) is lattice node (3, -2).
        let spec = GridSpec::explicit(6.0, -4.0, 6, 4, 2.0);
        let nodes = [(4, 1), (0, 1), (1, 1), (5, 3), (1, 1), (3, 1)];
        let runs = NodeRuns::of(&nodes, &spec);
        // Row 1 is lattice row -1: columns 0-1 (lattice 3-4) and 3-4
        // (lattice 6-7); row 3 is lattice row 1, column 5 (lattice 8).
        assert_eq!(runs.runs, vec![[-1, 3, 4], [-1, 6, 7], [1, 8, 8]]);
        assert_eq!(runs.nodes, 5);
        assert_eq!(runs.area_mm2(), 5.0 * 4.0);
        // On a grid one column further left, the same places.
        let wider = GridSpec::explicit(4.0, -4.0, 7, 4, 2.0);
        let mask = runs.mask_on(&wider).unwrap();
        let on: Vec<usize> = (0..mask.len()).filter(|&n| mask[n]).collect();
        assert_eq!(on, vec![8, 9, 11, 12, 27]);
        // Another pitch is another grid.
        assert!(
            runs.mask_on(&GridSpec::explicit(6.0, -4.0, 6, 4, 1.0))
                .is_none()
        );
    }

    #[test]
    fn a_zone_on_or_beside_a_marked_node_is_touched_and_a_distant_one_is_not() {
        // Two zones on a 6 x 4 grid: columns 0-1 of rows 0-1, and node
        // (5, 3). One marked node diagonal to the first zone's (1, 1).
        let mut counts = vec![0u16; 24];
        for n in [0, 1, 6, 7, 23] {
            counts[n] = 1;
        }
        let members = components(&counts, 6, 4);
        assert_eq!(members, vec![vec![0, 1, 6, 7], vec![23]]);
        let mut marked = vec![false; 24];
        marked[2 * 6 + 2] = true;
        assert_eq!(touched_by(&members, 6, 4, &marked), vec![true, false]);
        // On a zone's own node it touches too; two columns away it does not.
        let mut marked = vec![false; 24];
        marked[23] = true;
        assert_eq!(touched_by(&members, 6, 4, &marked), vec![false, true]);
        let mut marked = vec![false; 24];
        marked[3] = true;
        assert_eq!(touched_by(&members, 6, 4, &marked), vec![false, false]);
    }
}
