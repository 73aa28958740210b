//! A study's progress stages: what every part of the harness reports to
//! the `Progress` it is given.

/// `work` reported to `progress` as one stage, `what` with `total` steps
/// (a spinner when `None`): the stage ends however `work` returns.
pub(crate) fn in_stage<T>(
    progress: &dyn crate::Progress,
    what: &str,
    total: Option<u64>,
    work: impl FnOnce() -> T,
) -> T {
    progress.begin(what, total);
    let done = work();
    progress.end();
    done
}

/// The stage in which a study's grid slides are compared with the exact
/// traces of `pairs` start-angle pairs: minutes on a large part.
pub(crate) fn comparing(pairs: usize) -> String {
    format!("grid against exact: {pairs} start-angle pairs")
}

/// The stage in which the analysis's colliding area is run at each of
/// `angles` angles and the node nearest each exact strike found in it.
pub(crate) fn covering(angles: usize) -> String {
    format!("grid: the analysis's area at {angles} angles")
}
