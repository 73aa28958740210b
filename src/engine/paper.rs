//! The paper-literal push and slide (Inui, Gunji and Umezu, sections 3 and
//! 4): the reference the fast path is tested against and the baseline it is
//! timed against.
//!
//! Per start row and angle: the rows in front of the first start are merged
//! into one list in distance order (a k-way merge: the rows share one pitch);
//! each start to its left reuses that list with its first layer dropped; a
//! slide that reaches a point already found (struck) by an earlier slide of
//! the same start row and angle finishes that point's tie group and is
//! cancelled: both slides see the same groups from there on, and both
//! levels drop to the group's lowest height there (the earlier one struck a
//! node of it, and this one's level is at or above the earlier one's), so
//! the rest would strike nothing new. Under the window rule the strikes
//! also read the level `W` mm back, where the two slides still differ, so
//! the cancellation waits until every window looks back past that group
//! (SPEC: the two slides' levels must agree over the last `W` mm). A slide
//! that meets no colliding point scans to the end of the grid, so this is
//! slow on flat parts by design.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::engine::padded::{PaddedGrid, fmin};
use crate::engine::push::push_start_literal;
use crate::grid::NODE_TOL;
use crate::kneeform::GridFootprint;
use crate::strike::{LevelHistory, Meeting, RateEstimate, StrikeRule};

/// One node of the merged list: its padded index, the layer it belongs to
/// counted from the row's first start (`nx - 1`), and its tie group.
#[derive(Debug, Clone, Copy)]
struct Entry {
    node: usize,
    layer: usize,
    group: u32,
    /// Slide distance (mm) from the row's first start.
    d: f64,
}

/// Marks of the nodes found in the current start row: a node is found when
/// its stamp equals the row's.
#[derive(Debug, Default)]
pub(crate) struct PaperScratch {
    found: Vec<u32>,
    stamp: u32,
    list: Vec<Entry>,
}

/// Work counters of the paper algorithm, for the benchmark.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct PaperCounts {
    /// Merged-list entries visited by slides.
    pub visited: u64,
    /// Slides cancelled at an already-found point.
    pub cancelled: u64,
}

/// Pushes and slides every start of start row `j0` literally and ORs the
/// colliding nodes into `mask` (padded like `grid`). Returns the number of
/// placed starts.
pub(crate) fn paper_row(
    grid: &PaddedGrid,
    fp: &GridFootprint,
    j0: usize,
    rule: &StrikeRule,
    mask: &mut [u8],
    scratch: &mut PaperScratch,
    counts: &mut PaperCounts,
) -> usize {
    let nx = grid.spec.nx;
    let p = grid.spec.pitch;
    if scratch.found.len() != grid.h.len() {
        scratch.found = vec![0; grid.h.len()];
        scratch.stamp = 0;
    }
    scratch.stamp = scratch.stamp.wrapping_add(1);
    if scratch.stamp == 0 {
        scratch.found.fill(0);
        scratch.stamp = 1;
    }
    let stamp = scratch.stamp;

    // The merged list of the first start, i0 = nx - 1: every node in front
    // in every footprint row, in order of slide distance d = d0 + layer * p.
    scratch.list.clear();
    let mut heap = BinaryHeap::new();
    for (r, row) in fp.rows.iter().enumerate() {
        if grid.row_of(j0, row.dj).is_some() {
            heap.push(Reverse((Dist(row.d0), row.dj, r, 0usize)));
        }
    }
    let mut group = 0u32;
    let mut last_d = f64::NAN;
    while let Some(Reverse((Dist(d), dj, r, layer))) = heap.pop() {
        let row = &fp.rows[r];
        let i = (nx - 1) as i64 + i64::from(row.kf) - layer as i64;
        if i < 0 {
            continue;
        }
        let j = grid.row_of(j0, dj).expect("row was checked");
        if i < nx as i64 {
            if !scratch.list.is_empty() && d - last_d > NODE_TOL {
                group += 1;
            }
            last_d = d;
            scratch.list.push(Entry {
                node: grid.index(j as i64, 0) + i as usize,
                layer,
                group,
                d,
            });
        }
        let next = layer + 1;
        heap.push(Reverse((Dist(row.d0 + next as f64 * p), dj, r, next)));
    }

    let mut placed = 0;
    let mut head = 0;
    for i0 in (0..nx).rev() {
        // Moving one node left drops the first layer of the list.
        let dropped = nx - 1 - i0;
        while head < scratch.list.len() && scratch.list[head].layer < dropped {
            head += 1;
        }
        let yr = push_start_literal(grid, fp, i0, j0);
        if yr == f64::INFINITY {
            continue;
        }
        placed += 1;
        // Distances from this start: the row's first start's, less the
        // columns between them.
        let shift = dropped as f64 * p;
        let mut f = yr;
        let mut history = LevelHistory::new(yr);
        // The travel past which the slide repeats an earlier one's.
        let mut cancel_at = f64::INFINITY;
        let mut k = head;
        while k < scratch.list.len() {
            let g = scratch.list[k].group;
            let s = scratch.list[k].d - shift;
            if s >= cancel_at {
                counts.cancelled += 1;
                break;
            }
            let earlier = history.earlier(s, rule.window);
            let mut gmin = f64::INFINITY;
            let mut reached_found = false;
            while k < scratch.list.len() && scratch.list[k].group == g {
                let node = scratch.list[k].node;
                let h = grid.h[node];
                reached_found |= scratch.found[node] == stamp;
                // The node behind is the next column (padding past the
                // grid's +x edge is `+inf`).
                let met = Meeting {
                    h,
                    behind: grid.h[node + 1],
                    level: f,
                    earlier,
                    pitch: p,
                };
                if rule.strikes(met) {
                    mask[node] = 1;
                    scratch.found[node] = stamp;
                }
                gmin = fmin(gmin, h);
                k += 1;
                counts.visited += 1;
            }
            f = fmin(f, gmin);
            history.push(s, f);
            if reached_found && cancel_at == f64::INFINITY {
                cancel_at = match rule.rate {
                    // Both slides now hold one level: what is left repeats.
                    RateEstimate::XSlope => s,
                    // The rest repeats once the windows of both look back
                    // past this group only, with a pitch to spare for the
                    // rounding of the two slides' travels.
                    RateEstimate::Window => s + rule.window + p,
                };
                if cancel_at == s {
                    counts.cancelled += 1;
                    break;
                }
            }
        }
    }
    placed
}

/// A distance ordered by `total_cmp`, for the merge heap.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Dist(f64);

impl Eq for Dist {}

impl PartialOrd for Dist {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Dist {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}
