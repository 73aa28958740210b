//! Which part, read how, by which kneeform: the record that opens every
//! study's JSON ([`RunIdentity`]), a leaf every study's summary uses.

use serde::{Deserialize, Serialize};

use crate::input::PartFile;

/// Which part, read how, by which kneeform: the record that opens every
/// study's JSON (`verify.json`, `converge.json`, both approaches'),
/// flattened into it, so the files read as they always did. `kneeform
/// report` matches a study to its run by it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunIdentity {
    /// Version of kneeform.
    pub kneeform_version: String,
    /// The part (STL or scenario file) as given.
    pub input_file: String,
    /// SHA-256 of the part file's bytes (hex), as `summary.json`'s
    /// `sha256`.
    #[serde(default)]
    pub input_sha256: String,
    /// Factor from the file's units to mm.
    #[serde(default = "unit_scale")]
    pub scale: f64,
    /// `left` or `right`.
    #[serde(default = "left_side")]
    pub side: crate::Side,
    /// `--frame`: the map from the part's coordinates into vehicle
    /// coordinates; absent without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<crate::frame::FrameRecord>,
}

impl RunIdentity {
    /// The identity of a study of `input` by this build.
    pub fn of(input: &PartFile) -> RunIdentity {
        RunIdentity {
            kneeform_version: env!("CARGO_PKG_VERSION").into(),
            input_file: input.path.display().to_string(),
            input_sha256: input.sha256.clone(),
            scale: input.scale,
            side: input.side,
            frame: input.frame.record(),
        }
    }
}

/// `scale` of files written before it was recorded.
pub(crate) fn unit_scale() -> f64 {
    1.0
}

/// `side` of files written before it was recorded.
pub(crate) fn left_side() -> crate::Side {
    crate::Side::Left
}
