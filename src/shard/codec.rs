//! The little-endian encoding of a study shard's `shard.bin`
//! ([`super::study`]): lengths and counts as u64, every f64 as its bits
//! (infinities, NaN and -0.0 read back as written), and a start-angle
//! pair as its status, node, metric values and points ([`put_pair`],
//! [`Reader::pair`]); a direct study's position-angle pair as its row's
//! status, values and counts ([`put_direct_pair`],
//! [`Reader::direct_pair`]).
//!
//! **Invariant:** reading is bounds-checked: a cut or damaged file is an
//! error, never a panic, and a count larger than the bytes left allocates
//! nothing.

use crate::harness::compare::{PairResult, STATUSES, row_of};
use crate::harness::direct::{DIRECT_STATUSES, DirectPair, DirectRow};
use crate::harness::metrics::{StartComparison, StartPoints};
use kneeform_oracle::FailureReason;

pub(super) fn put_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_le_bytes());
}

pub(super) fn put_f64(out: &mut Vec<u8>, v: f64) {
    put_u64(out, v.to_bits());
}

pub(super) fn put_f64s(out: &mut Vec<u8>, v: &[f64]) {
    put_u64(out, v.len() as u64);
    for &x in v {
        put_f64(out, x);
    }
}

pub(super) fn put_opt(out: &mut Vec<u8>, v: Option<f64>) {
    out.push(u8::from(v.is_some()));
    put_f64(out, v.unwrap_or(0.0));
}

pub(super) fn put_points(out: &mut Vec<u8>, v: &[[f64; 2]]) {
    put_u64(out, v.len() as u64);
    for p in v {
        put_f64(out, p[0]);
        put_f64(out, p[1]);
    }
}

pub(super) fn put_nodes(out: &mut Vec<u8>, v: &[(usize, usize)]) {
    put_u64(out, v.len() as u64);
    for &(i, j) in v {
        put_u64(out, i as u64);
        put_u64(out, j as u64);
    }
}

/// One pair: status, node, then its comparison's values and points, the
/// grid's nodes and the snapped exact strikes (the row is rebuilt from
/// them by [`row_of`], as the comparison builds it).
pub(super) fn put_pair(out: &mut Vec<u8>, pair: &PairResult) {
    let status = STATUSES
        .iter()
        .position(|s| *s == pair.row.status)
        .unwrap_or(STATUSES.len());
    out.push(status as u8);
    put_u64(out, pair.row.i as u64);
    put_u64(out, pair.row.j as u64);
    let c = &pair.cmp;
    for v in [
        c.push_error,
        c.first_contact_error,
        c.first_contact_error_decided,
        c.first_contact_error_blind,
        c.first_contact_late_inside,
        c.miss_half_pitch,
        c.miss_quarter_pitch,
    ] {
        put_opt(out, v);
    }
    out.push(flags(c));
    out.push(c.oracle_failure.map_or(0, |r| 1 + failure_index(r)));
    for v in [
        &c.miss,
        &c.miss_decided,
        &c.miss_blind,
        &c.false_alarm,
        &c.false_alarm_decided,
        &c.false_alarm_blind,
        &c.unmatched_deflection,
        &c.unmatched_deflection_decided,
        &c.unmatched_deflection_inside,
        &c.unmatched_deflection_blind,
        &c.level_clearance,
        &c.level_bound,
    ] {
        put_f64s(out, v);
    }
    for flags in [&c.false_alarm_explained, &c.miss_rim, &c.miss_brief] {
        put_u64(out, flags.len() as u64);
        out.extend(flags.iter().map(|&b| u8::from(b)));
    }
    put_u64(out, c.exact_strikes as u64);
    put_u64(out, c.undecided as u64);
    put_u64(out, c.blind_strikes as u64);
    for v in c.points.sets() {
        put_points(out, v);
    }
    put_nodes(out, &pair.grid_nodes);
    put_nodes(out, &pair.snapped);
}

/// The oracle's failure reasons, in the order a shard's file numbers them
/// (from 1; 0 is no failure).
const FAILURE_REASONS: [FailureReason; 5] = [
    FailureReason::CastNotConverged,
    FailureReason::UnconfirmedMiss,
    FailureReason::PenetratingStart,
    FailureReason::CastBudgetExhausted,
    FailureReason::Unsupported,
];

fn failure_index(reason: FailureReason) -> u8 {
    FAILURE_REASONS
        .iter()
        .position(|&r| r == reason)
        .map_or(u8::MAX, |k| k as u8)
}

/// A pair's yes-no facts, one bit each: whether its exact knee-form
/// touched a blind spot, its push contact lies on one, its push error and
/// its first grid strike are explained by the level error.
fn flags(c: &StartComparison) -> u8 {
    u8::from(c.blind)
        | u8::from(c.push_blind) << 1
        | u8::from(c.push_explained) << 2
        | u8::from(c.first_contact_explained) << 3
}

/// One direct pair: its row's status, levels, contact and counts, and
/// whether the engine's level differed; the position and angle are the
/// shard's (the reader is given them, as [`Reader::direct_pair`]).
pub(super) fn put_direct_pair(out: &mut Vec<u8>, pair: &DirectPair) {
    let r = &pair.row;
    let status = DIRECT_STATUSES
        .iter()
        .position(|s| *s == r.status)
        .unwrap_or(DIRECT_STATUSES.len());
    out.push(status as u8);
    for v in [
        r.grid_level,
        r.exact_level,
        r.level_error,
        r.exact_y,
        r.exact_z,
        r.contact_distance,
    ] {
        put_opt(out, v);
    }
    put_u64(out, r.grid_contacted as u64);
    put_u64(out, r.exact_ties as u64);
    out.push(u8::from(pair.engine_mismatch));
}

/// Reads `shard.bin`; every read checks the bytes left, and a length
/// never exceeds them (a damaged length cannot make a huge allocation).
pub(super) struct Reader<'a> {
    bin: &'a [u8],
    /// Bytes read so far.
    pub(super) at: usize,
}

impl<'a> Reader<'a> {
    /// A reader of `bin` from its start.
    pub(super) fn new(bin: &'a [u8]) -> Reader<'a> {
        Reader { bin, at: 0 }
    }

    pub(super) fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bin.len())
            .ok_or("it ends early")?;
        let bytes = &self.bin[self.at..end];
        self.at = end;
        Ok(bytes)
    }

    pub(super) fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }

    pub(super) fn u64(&mut self) -> Result<u64, String> {
        let b = self.take(8)?;
        Ok(u64::from_le_bytes(b.try_into().map_err(|_| "8 bytes")?))
    }

    pub(super) fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_bits(self.u64()?))
    }

    /// A count of items of at least `size` bytes each still to come.
    pub(super) fn count(&mut self, size: usize) -> Result<usize, String> {
        let n = self.u64()?;
        let left = (self.bin.len() - self.at) / size.max(1);
        usize::try_from(n)
            .ok()
            .filter(|&n| n <= left)
            .ok_or_else(|| format!("a count of {n} where {left} at most fit"))
    }

    pub(super) fn len(&mut self) -> Result<usize, String> {
        usize::try_from(self.u64()?).map_err(|_| "a length beyond memory".to_string())
    }

    pub(super) fn f64s(&mut self) -> Result<Vec<f64>, String> {
        let n = self.count(8)?;
        (0..n).map(|_| self.f64()).collect()
    }

    pub(super) fn opt(&mut self) -> Result<Option<f64>, String> {
        let some = match self.u8()? {
            0 => false,
            1 => true,
            b => return Err(format!("an option flag {b}")),
        };
        let v = self.f64()?;
        Ok(some.then_some(v))
    }

    pub(super) fn bools(&mut self) -> Result<Vec<bool>, String> {
        let n = self.count(1)?;
        (0..n)
            .map(|_| match self.u8()? {
                0 => Ok(false),
                1 => Ok(true),
                b => Err(format!("a flag {b}")),
            })
            .collect()
    }

    pub(super) fn points(&mut self) -> Result<Vec<[f64; 2]>, String> {
        let n = self.count(16)?;
        (0..n).map(|_| Ok([self.f64()?, self.f64()?])).collect()
    }

    pub(super) fn nodes(&mut self) -> Result<Vec<(usize, usize)>, String> {
        let n = self.count(16)?;
        (0..n).map(|_| Ok((self.len()?, self.len()?))).collect()
    }

    /// A direct pair ([`put_direct_pair`]) of the position `[y, z]` at
    /// `angle_deg`.
    pub(super) fn direct_pair(
        &mut self,
        [y, z]: [f64; 2],
        angle_deg: f64,
    ) -> Result<DirectPair, String> {
        let status = self.u8()?;
        let status = DIRECT_STATUSES
            .get(usize::from(status))
            .ok_or(format!("a direct status {status}"))?;
        let mut row = DirectRow {
            y,
            z,
            angle_deg,
            status: (*status).into(),
            grid_level: self.opt()?,
            exact_level: self.opt()?,
            level_error: self.opt()?,
            exact_y: self.opt()?,
            exact_z: self.opt()?,
            contact_distance: self.opt()?,
            grid_contacted: 0,
            exact_ties: 0,
        };
        row.grid_contacted = self.len()?;
        row.exact_ties = self.len()?;
        let engine_mismatch = match self.u8()? {
            0 => false,
            1 => true,
            b => return Err(format!("an engine mismatch flag {b}")),
        };
        Ok(DirectPair {
            row,
            engine_mismatch,
        })
    }

    pub(super) fn pair(&mut self, angle_deg: f64) -> Result<PairResult, String> {
        let status = *STATUSES
            .get(usize::from(self.u8()?))
            .ok_or("a start-angle pair of unknown status")?;
        let (i, j) = (self.len()?, self.len()?);
        let (push_error, first_contact_error, first_contact_error_decided) =
            (self.opt()?, self.opt()?, self.opt()?);
        let first_contact_error_blind = self.opt()?;
        let first_contact_late_inside = self.opt()?;
        let (miss_half_pitch, miss_quarter_pitch) = (self.opt()?, self.opt()?);
        let flags = self.u8()?;
        if flags >> 4 != 0 {
            return Err(format!("pair flags {flags}"));
        }
        let oracle_failure = match self.u8()? {
            0 => None,
            k => Some(
                *FAILURE_REASONS
                    .get(usize::from(k) - 1)
                    .ok_or_else(|| format!("an oracle failure reason {k}"))?,
            ),
        };
        let mut cmp = StartComparison {
            push_error,
            push_blind: flags & 2 != 0,
            push_explained: flags & 4 != 0,
            first_contact_error,
            first_contact_error_decided,
            first_contact_error_blind,
            first_contact_explained: flags & 8 != 0,
            first_contact_late_inside,
            miss: self.f64s()?,
            miss_decided: self.f64s()?,
            miss_blind: self.f64s()?,
            false_alarm: self.f64s()?,
            false_alarm_decided: self.f64s()?,
            false_alarm_blind: self.f64s()?,
            unmatched_deflection: self.f64s()?,
            unmatched_deflection_decided: self.f64s()?,
            unmatched_deflection_inside: self.f64s()?,
            unmatched_deflection_blind: self.f64s()?,
            level_clearance: self.f64s()?,
            level_bound: self.f64s()?,
            false_alarm_explained: self.bools()?,
            miss_rim: self.bools()?,
            miss_brief: self.bools()?,
            miss_half_pitch,
            miss_quarter_pitch,
            oracle_failure,
            exact_strikes: self.len()?,
            undecided: self.len()?,
            blind: flags & 1 != 0,
            blind_strikes: self.len()?,
            points: StartPoints::default(),
        };
        for set in cmp.points.sets_mut() {
            *set = self.points()?;
        }
        Ok(PairResult {
            row: row_of(i, j, angle_deg, status, &cmp),
            cmp,
            grid_nodes: self.nodes()?,
            snapped: self.nodes()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn pair() -> PairResult {
        let cmp = StartComparison {
            push_error: Some(-0.25),
            push_blind: true,
            push_explained: false,
            first_contact_error: None,
            first_contact_error_decided: Some(f64::MIN_POSITIVE),
            first_contact_error_blind: Some(-2.0),
            first_contact_explained: true,
            first_contact_late_inside: Some(0.75),
            miss: vec![1.5, f64::INFINITY],
            miss_decided: vec![f64::INFINITY],
            miss_rim: vec![true],
            miss_brief: vec![false],
            miss_half_pitch: Some(0.25),
            miss_quarter_pitch: Some(f64::INFINITY),
            miss_blind: vec![0.5],
            false_alarm: vec![0.1 + 0.2, 7.0],
            false_alarm_decided: vec![0.3],
            false_alarm_explained: vec![true],
            false_alarm_blind: vec![7.0],
            unmatched_deflection: vec![3.0],
            unmatched_deflection_decided: vec![-0.0],
            unmatched_deflection_inside: vec![2.5],
            unmatched_deflection_blind: Vec::new(),
            level_clearance: vec![0.01],
            level_bound: vec![0.25],
            oracle_failure: Some(FailureReason::UnconfirmedMiss),
            exact_strikes: 2,
            undecided: 1,
            blind: true,
            blind_strikes: 1,
            points: StartPoints {
                grid: vec![[1.0, 2.0], [9.0, 9.5]],
                grid_decided: vec![[1.0, 2.0]],
                grid_unexplained: Vec::new(),
                grid_blind: vec![[9.0, 9.5]],
                strikes: vec![[3.0, 4.0], [5.0, 6.0]],
                decided: vec![[5.0, 6.0]],
                blind: vec![[3.0, 4.0]],
                decided_inside: Vec::new(),
                decided_refined: vec![[0.5, 1.5]],
                possible: Vec::new(),
                push: vec![[-7.5, 8.25]],
            },
        };
        PairResult {
            row: row_of(4, 9, -30.0, "grid_not_placed", &cmp),
            cmp,
            grid_nodes: vec![(1, 2), (3, 4)],
            snapped: vec![(5, 6)],
        }
    }

    #[test]
    fn a_pair_reads_back_bit_for_bit() {
        let p = pair();
        let mut bin = Vec::new();
        put_pair(&mut bin, &p);
        let mut r = Reader { bin: &bin, at: 0 };
        let back = r.pair(-30.0).unwrap();
        assert_eq!(r.at, bin.len());
        // PartialEq on f64 would take -0.0 for 0.0: compare the bits too.
        assert_eq!(back, p);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&back.cmp.unmatched_deflection_decided),
            bits(&p.cmp.unmatched_deflection_decided)
        );
    }

    #[test]
    fn a_cut_or_damaged_pair_is_an_error_not_a_panic() {
        let mut bin = Vec::new();
        put_pair(&mut bin, &pair());
        for end in 0..bin.len() {
            let mut r = Reader {
                bin: &bin[..end],
                at: 0,
            };
            assert!(r.pair(0.0).is_err(), "cut at {end}");
        }
        // A count far beyond the bytes left allocates nothing.
        let mut huge = vec![0u8];
        put_u64(&mut huge, 0);
        put_u64(&mut huge, 0);
        for _ in 0..3 {
            put_opt(&mut huge, None);
        }
        put_u64(&mut huge, u64::MAX);
        let mut r = Reader { bin: &huge, at: 0 };
        assert!(r.pair(0.0).is_err());
        // An unknown status.
        let mut bad = bin.clone();
        bad[0] = STATUSES.len() as u8;
        assert!(Reader { bin: &bad, at: 0 }.pair(0.0).is_err());
    }

    #[test]
    fn a_direct_pair_reads_back_bit_for_bit_and_a_cut_one_is_an_error() {
        let p = DirectPair {
            row: DirectRow {
                y: 12.0,
                z: -4.0,
                angle_deg: 30.0,
                status: "both".into(),
                grid_level: Some(-0.0),
                exact_level: Some(0.1 + 0.2),
                level_error: Some(f64::MIN_POSITIVE),
                exact_y: Some(11.5),
                exact_z: None,
                contact_distance: Some(f64::INFINITY),
                grid_contacted: 7,
                exact_ties: 2,
            },
            engine_mismatch: true,
        };
        let mut bin = Vec::new();
        put_direct_pair(&mut bin, &p);
        let mut r = Reader { bin: &bin, at: 0 };
        let back = r.direct_pair([12.0, -4.0], 30.0).unwrap();
        assert_eq!(r.at, bin.len());
        assert_eq!(back, p);
        // PartialEq on f64 would take -0.0 for 0.0: compare the bits too.
        assert_eq!(
            back.row.grid_level.map(f64::to_bits),
            Some((-0.0f64).to_bits())
        );
        for end in 0..bin.len() {
            let mut r = Reader {
                bin: &bin[..end],
                at: 0,
            };
            assert!(r.direct_pair([0.0, 0.0], 0.0).is_err(), "cut at {end}");
        }
        // An unknown status, an unknown flag.
        let mut bad = bin.clone();
        bad[0] = DIRECT_STATUSES.len() as u8;
        assert!(
            Reader { bin: &bad, at: 0 }
                .direct_pair([0.0, 0.0], 0.0)
                .is_err()
        );
        let mut bad = bin.clone();
        *bad.last_mut().unwrap() = 2;
        assert!(
            Reader { bin: &bad, at: 0 }
                .direct_pair([0.0, 0.0], 0.0)
                .is_err()
        );
    }
}
