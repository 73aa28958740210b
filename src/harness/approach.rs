//! What each approach does its own way in every study ([`StudyApproach`]),
//! and the records of a study that hold it without naming it: the
//! options ([`StudyOptions`]), the result ([`Study`]) and the files and
//! words it gives ([`StudyFile`], [`Said`]).
//!
//! The one study path (`study`), the shards (`crate::shard::study`), the
//! writer (`crate::output::write_study`) and the printer (the binary's)
//! call only these; push-and-slide's implementation is `slide`'s, the
//! direct approach's `direct`'s, and [`super::studies_of`] names them.

use std::any::Any;
use std::io;
use std::ops::Range;
use std::path::Path;

use super::codec::Reader;
use super::compare::StartSelection;
use super::converge::ConvergeOptions;
use super::error::HarnessError;
use super::method::Method;
use super::pairs::{Pairs, PitchPart};
use super::sharded::{KnownSummary, StudyKind, StudyPart, StudySummary};
use super::trace::Fault;
use super::verify::VerifyOptions;
use crate::frame::Approach;
use crate::grid::GridSpec;
use crate::input::PartFile;
use crate::setup::Setup;

/// Which study, with its options.
#[derive(Debug, Clone, Copy)]
pub enum StudyOptions<'a> {
    /// `verify`: one pitch, the setup's.
    Verify(&'a VerifyOptions),
    /// `converge`: a ladder of pitches.
    Converge(&'a ConvergeOptions),
}

impl StudyOptions<'_> {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), HarnessError> {
        match self {
            StudyOptions::Verify(o) => o.validate(),
            StudyOptions::Converge(o) => o.validate(),
        }
    }

    /// Which study.
    pub(crate) fn kind(&self) -> StudyKind {
        match self {
            StudyOptions::Verify(_) => StudyKind::Verify,
            StudyOptions::Converge(_) => StudyKind::Converge,
        }
    }

    /// The pitches, coarsest first (mm): verify's one (the setup's),
    /// converge's ladder.
    pub(crate) fn pitches(&self, setup: &Setup) -> Vec<f64> {
        match self {
            StudyOptions::Verify(_) => vec![setup.pitch],
            StudyOptions::Converge(o) => o.pitches.clone(),
        }
    }

    /// The longest the oracle may take (s): beyond it, refused.
    pub fn budget_s(&self) -> Option<f64> {
        match self {
            StudyOptions::Verify(o) => o.budget_s,
            StudyOptions::Converge(o) => o.budget_s,
        }
    }

    /// Which starts.
    pub(crate) fn selection(&self) -> &StartSelection {
        match self {
            StudyOptions::Verify(o) => &o.selection,
            StudyOptions::Converge(o) => &o.selection,
        }
    }

    /// The tie band's growth with the pitch (per mm).
    pub(crate) fn tie_band_per_mm(&self) -> f64 {
        match self {
            StudyOptions::Verify(o) => o.tie_band_per_mm,
            StudyOptions::Converge(o) => o.tie_band_per_mm,
        }
    }

    /// The tolerance (mm): verify's always, converge's when asked for.
    pub(crate) fn tolerance(&self) -> Option<f64> {
        match self {
            StudyOptions::Verify(o) => Some(o.tolerance),
            StudyOptions::Converge(o) => o.tolerance,
        }
    }
}

/// What a share of a study knows when its pitches are compared: what its
/// summary is made from ([`StudyApproach::summary_as_known`]).
pub(crate) struct ShareKnown<'a> {
    pub input: &'a PartFile,
    pub setup: &'a Setup,
    pub options: StudyOptions<'a>,
    /// The coarsest grid.
    pub coarse: &'a GridSpec,
    /// Every start of the study (all shards').
    pub starts: usize,
    /// The share's pitches, coarsest first.
    pub parts: &'a [PitchPart],
    /// Seconds sampling the coarsest grid, and of the oracle.
    pub sample_s: f64,
    pub oracle_s: f64,
}

/// What a study does its own way for one approach, beyond its steps
/// ([`Method`]): its summaries, its pairs in a shard's file, its merge.
/// A new approach implements it in its own module, and
/// [`super::studies_of`] names it.
pub(crate) trait StudyApproach: Sync {
    /// `shard.json`'s word for this approach's study `kind` (`verify`,
    /// `converge-direct`, ...), unique over the approaches.
    fn kind_word(&self, kind: StudyKind) -> &'static str;
    /// The most a comparison on the grid `spec` holds at once in finer
    /// grids sampled to refine a miss (bytes), on `threads` threads; none
    /// by default.
    fn refinement_bytes(&self, _setup: &Setup, _spec: &GridSpec, _threads: usize) -> f64 {
        0.0
    }
    /// The approach, its study `kind` and the study's word
    /// ([`StudyApproach::kind_word`]): what names a summary of it.
    fn named(&self, kind: StudyKind) -> (Approach, StudyKind, &'static str) {
        (self.approach(), kind, self.kind_word(kind))
    }
    /// The approach whose studies these are.
    fn approach(&self) -> Approach;
    /// A shard of this approach's study `kind`, in words.
    fn shard_words(&self, kind: StudyKind) -> &'static str;
    /// The study `options` laid on `input` with `coarse` (the setup at
    /// the coarsest pitch): its coarsest grid and starts, not yet traced.
    fn lay<'a>(
        &self,
        input: &'a PartFile,
        coarse: &Setup,
        options: StudyOptions,
        fault: Option<Fault>,
    ) -> Result<Box<dyn Method + 'a>, HarnessError>;
    /// The study's summary as a share knows it: the part's identity, every
    /// setting and the share's own seconds, with the statistics of no
    /// start (the merge sets them from every share's pairs; a share's own
    /// could be infinite, which JSON cannot say).
    fn summary_as_known(&self, share: ShareKnown) -> StudySummary;
    /// The summary of study `kind` read back from a shard's JSON.
    fn summary_from_json(
        &self,
        kind: StudyKind,
        json: serde_json::Value,
    ) -> Result<Box<dyn KnownSummary>, String>;
    /// The fields of a `kind` summary that a merge sets from every share's
    /// pairs (statistics, fits, the verdict), with their values for a study
    /// of no start: `shard.json` leaves them out.
    fn merged_fields(&self, kind: StudyKind) -> serde_json::Value;
    /// The fields of a `kind` summary that hold a share's own clock
    /// readings.
    fn clock_fields(&self, kind: StudyKind) -> &'static [&'static str];
    /// `count` pairs of one pitch read from a shard's `shard.bin` (as
    /// [`super::pairs::Pair::put`] wrote them), pair `k` of the start or
    /// position and angle (degrees) `at(k)`.
    fn read_pairs(
        &self,
        r: &mut Reader,
        count: usize,
        at: &dyn Fn(usize) -> ([f64; 2], f64),
    ) -> Result<Pairs, String>;
    /// The study of the shares `parts` (every shard once, in shard order),
    /// its pairs moved back in the unsharded order and assembled, and
    /// `summary` set from them; `None` when the shares are not of one
    /// study of this approach.
    fn merge(&self, summary: StudySummary, parts: &mut [StudyPart]) -> Option<Study>;
}

/// A study's result, as its approach types it: what its files hold and
/// what it says.
pub(crate) trait StudyResult: Any + std::fmt::Debug + Send {
    /// Its files, in the order they are written.
    fn files(&self) -> Vec<StudyFile<'_>>;
    /// What it says of itself (its results are in `out`).
    fn said(&self, out: &Path) -> Said;
    /// The line saying how long its oracle took, for a study that says
    /// it before its files are written (`angles`: the setup's count).
    fn oracle_line(&self, angles: usize) -> Option<String> {
        let _ = angles;
        None
    }
}

/// A study's result, for either study and approach: [`Study::said`] for
/// its words; [`Study::downcast`] for the typed result
/// ([`super::Verification`], [`super::Convergence`],
/// [`super::DirectVerification`], [`super::DirectConvergence`]).
#[derive(Debug)]
pub struct Study(Box<dyn StudyResult>);

impl Study {
    /// `result`, as a study.
    pub(crate) fn of(result: impl StudyResult) -> Study {
        Study(Box::new(result))
    }

    /// The typed result, when it is a `T` (else the study back).
    pub fn downcast<T: Any>(self) -> Result<T, Study> {
        if (self.0.as_ref() as &dyn Any).is::<T>() {
            let any: Box<dyn Any> = self.0;
            Ok(*any.downcast::<T>().expect("checked above"))
        } else {
            Err(self)
        }
    }

    /// What the study says of itself, its results being in `out`: the
    /// lines `verify`, `converge` and `kneeform merge` print, and a
    /// verification's outcome.
    pub fn said(&self, out: &Path) -> Said {
        self.0.said(out)
    }

    /// The line saying how long a convergence study's oracle took (`None`
    /// for a verification, which says it among its figures).
    pub fn oracle_line(&self, angles: usize) -> Option<String> {
        self.0.oracle_line(angles)
    }

    /// Its files, in the order they are written.
    pub(crate) fn files(&self) -> Vec<StudyFile<'_>> {
        self.0.files()
    }
}

/// What a study says of itself: its lines (to the standard error) and
/// its outcome (`verify`'s exit status:
/// [`crate::summary::Outcome::exit_code`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Said {
    /// The lines, in order.
    pub lines: Vec<String>,
    /// A verification's outcome; `None` for a convergence study, which
    /// judges each pitch in its files and exits 0 once written.
    pub outcome: Option<crate::summary::Outcome>,
}

/// One file of a study's results, as its approach describes it; the
/// output writes it into the study's directory.
pub(crate) enum StudyFile<'a> {
    /// A text file (CSV, JSON): its name, and what writes it.
    Text(String, TextWriter<'a>),
    /// A log-log plot against the pitch (a PNG).
    Plot(LogLogPlot),
}

/// What writes a text file's bytes.
pub(crate) type TextWriter<'a> = Box<dyn Fn(&mut dyn io::Write) -> io::Result<()> + 'a>;

impl<'a> StudyFile<'a> {
    /// The CSV file `name`, one row per item of `rows` under a header of
    /// their fields.
    pub(crate) fn rows<T: serde::Serialize>(name: impl Into<String>, rows: &'a [T]) -> Self {
        StudyFile::csv(name, move |csv| {
            rows.iter().try_for_each(|row| csv.serialize(row))
        })
    }

    /// The CSV file `name`, its records written by `write`.
    pub(crate) fn csv(
        name: impl Into<String>,
        write: impl Fn(&mut csv::Writer<&mut dyn io::Write>) -> csv::Result<()> + 'a,
    ) -> Self {
        StudyFile::Text(
            name.into(),
            Box::new(move |out| {
                let mut csv = csv::Writer::from_writer(out);
                write(&mut csv)?;
                csv.flush()
            }),
        )
    }

    /// A verification's files, whatever its approach: `verify.csv` (one
    /// row per start or position and angle) and `verify.json`.
    pub(crate) fn verification<R, S>(rows: &'a [R], summary: &'a S) -> Vec<Self>
    where
        R: serde::Serialize,
        S: serde::Serialize,
    {
        vec![
            StudyFile::rows("verify.csv", rows),
            StudyFile::json("verify.json", summary),
        ]
    }

    /// A convergence study's files, whatever its approach: `converge.csv`
    /// (`table`: every metric at every pitch), `verify_<pitch>mm.csv` (each
    /// of `pitches`' rows, as `verify.csv` has them: where each figure of
    /// `converge.csv` comes from) and `converge.json`.
    pub(crate) fn convergence<R, S>(
        table: impl Fn(&mut csv::Writer<&mut dyn io::Write>) -> csv::Result<()> + 'a,
        pitches: impl Iterator<Item = (f64, &'a [R])>,
        summary: &'a S,
    ) -> Vec<Self>
    where
        R: serde::Serialize + 'a,
        S: serde::Serialize,
    {
        let mut files = vec![StudyFile::csv("converge.csv", table)];
        for (pitch, rows) in pitches {
            files.push(StudyFile::rows(format!("verify_{pitch}mm.csv"), rows));
        }
        files.push(StudyFile::json("converge.json", summary));
        files
    }

    /// The JSON file `name`: `value`, pretty, with a final newline.
    pub(crate) fn json<T: serde::Serialize>(name: impl Into<String>, value: &'a T) -> Self {
        StudyFile::Text(
            name.into(),
            Box::new(move |out| {
                let text = crate::summary::json_text(value)?;
                out.write_all(text.as_bytes())
            }),
        )
    }
}

/// A log-log plot against the pitch, as a study describes it: the output
/// draws it, its series coloured in order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LogLogPlot {
    /// The PNG's name.
    pub file: &'static str,
    pub caption: &'static str,
    /// The axes' names.
    pub x_desc: &'static str,
    pub y_desc: &'static str,
    /// The study's pitches (mm): the x axis's ticks.
    pub pitches: Vec<f64>,
    /// The y axis's range (positive).
    pub values: Range<f64>,
    /// Its lines.
    pub series: Vec<PlotLine>,
}

/// One line of a [`LogLogPlot`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PlotLine {
    /// Its words in the legend; `None` keeps it out (a plot of one line).
    pub label: Option<String>,
    /// (pitch, value), both positive.
    pub points: Vec<(f64, f64)>,
}
