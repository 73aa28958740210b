//! The working memory of an analysis, estimated before anything is
//! allocated from what the run will really hold, and the process's peak
//! measured after, so that the estimate can be held to account.
//!
//! At its peak an analysis holds, in bytes (`N` grid nodes, `Np` nodes of
//! the padded grid, `Nr` nodes of its real rows, `L` levels of the push's
//! window-minimum table, `A` angles, `T` threads, `Nw` nodes of a band's
//! reach window, `n` triangles):
//!
//! * the part: `72 n` (three f64 vertices per triangle);
//! * the height grid `8 N`, its padded copy `8 Np`, the ranks and
//!   thresholds, and the push's tables: the window minima `4 (L - 1) Nr`
//!   (level 0 is the ranks themselves) and the group bounds (these and the
//!   two items below are the engine's own figures,
//!   `working_bytes`);
//! * per band task running (at most `T`, and at most the bands there
//!   are): its reach window, strikes and probe-corner bits (`5.125 Nw`;
//!   the paper path's band mask `Np` where that is larger);
//! * under `--level surface`, its tables: the row spans and their tall
//!   windows, six copies of the heights, and the block minima (`56 N`),
//!   and each thread's fold of the angle's mask (`T N`);
//! * per angle in flight (at most `min(T, A)`): its mask (`N`);
//! * every finished angle's mask (`A N`, with the allocator's holes
//!   between them: `MASK_BYTES_PER_NODE`) and the composite (`2 N`);
//! * the writers' buffers (the colliding-area surface, the images), at most
//!   `WRITE_BYTES_PER_NODE` per node;
//! * reading the part, before all of these, the file and two copies of
//!   its triangles ([`MemoryEstimate::reading`]), and with `analyze`'s
//!   sample check, after them, the oracle's mesh and its BVH, `400 n`, on
//!   what the analysis keeps ([`MemoryEstimate::add_sample_check`]): the
//!   whole is the largest of the three phases;
//! * the program itself, `BASE_BYTES`, and each thread's stack and
//!   arena, `THREAD_BYTES` a thread.
//!
//! The figures were checked against the measured peak (`VmHWM`) on runs
//! from 40 MiB to 1.3 GiB (`tests/hostile.rs` holds the bound test).

use crate::grid::GridSpec;
use crate::kneeform::GridFootprint;
use crate::strike::StrikeRule;

/// The program before any part is read: code, the font, the thread pool,
/// and the allocator's slack, which moves one run's peak by as much as 12
/// MiB from another's (the wave at 1 mm, 3 angles, 2 threads: 122.7 to
/// 135.5 MiB over four runs, the last above an estimate with 10 MiB here).
pub(crate) const BASE_BYTES: f64 = 20.0 * MIB;

/// Bytes per grid node the writers may hold at once (the colliding-area
/// surface's vertices and faces, the images' pixels) beyond the
/// analysis's own buffers.
pub(crate) const WRITE_BYTES_PER_NODE: f64 = 4.0;

/// Bytes each worker thread holds beyond the buffers counted: its stack's
/// pages and what its allocator's arena keeps of the chunks it freed
/// (measured 0.7 MiB: the console at 2 mm, 31 angles, 16 threads, peaked
/// 10.8 MiB above the estimate without it).
pub(crate) const THREAD_BYTES: f64 = MIB;

/// Bytes a finished angle's mask holds per grid node: one, and the
/// allocator's holes between the masks, where each angle's larger padded
/// buffers were freed (measured 1.27 on 1801 angles at 2 and 4 mm).
pub(crate) const MASK_BYTES_PER_NODE: f64 = 1.4;

/// Bytes held per triangle of the part.
pub(crate) const BYTES_PER_TRIANGLE: f64 = 72.0;

/// Bytes the exact oracle's copy of the part holds per triangle at its
/// peak, while parry builds its BVH (the BVH's nodes twice over while it
/// refits them, its leaves, the mesh): 377 measured as the slope of
/// `analyze`'s peak over the bump at 1 and 3 million triangles, with its
/// sample check (`results/hostile.md`).
pub(crate) const ORACLE_BYTES_PER_TRIANGLE: f64 = 400.0;

/// Bytes a study holds per node of each pitch's grid: the heights and
/// the comparison's copy of them with the blind spots (`Cells`), about 20.
#[cfg(feature = "harness")]
pub(crate) const STUDY_GRID_BYTES_PER_NODE: f64 = 20.0;

const MIB: f64 = 1024.0 * 1024.0;

/// The items an analysis still holds once the engine is done.
const KEPT_AFTER_THE_ENGINE: [&str; 5] = ["program", "threads", "part", "height grid", "masks"];

/// The item by which reading the part holds more than a later phase.
const READING_BEYOND: &str = "reading the part, beyond the rest";

/// An estimate of an analysis's peak working memory, by item.
#[derive(Debug, Clone, PartialEq)]
pub struct MemoryEstimate {
    /// Each item and its bytes.
    pub items: Vec<(&'static str, f64)>,
}

impl MemoryEstimate {
    /// The estimate for analysing a part of `triangles` triangles on `spec`
    /// at the angles of `footprints` (laid on `spec`), `threads` angles at
    /// a time at most.
    pub fn analysis(
        spec: &GridSpec,
        footprints: &[GridFootprint],
        rule: &StrikeRule,
        triangles: usize,
        threads: usize,
    ) -> MemoryEstimate {
        let n = spec.nx as f64 * spec.nz as f64;
        let angles = footprints.len() as f64;
        let mut items = vec![
            ("program", BASE_BYTES),
            ("threads", THREAD_BYTES * threads as f64),
            ("part", BYTES_PER_TRIANGLE * triangles as f64),
        ];
        items.extend(crate::engine::working_bytes(
            spec, footprints, rule, threads,
        ));
        items.extend([
            ("masks", MASK_BYTES_PER_NODE * angles * n + 2.0 * n),
            ("writers", WRITE_BYTES_PER_NODE * n),
        ]);
        MemoryEstimate { items }
    }

    /// Adds the sample check's working memory (`analyze`'s check against
    /// the exact oracle, after the analysis): by then the engine's
    /// buffers are freed, and the check holds what the analysis keeps
    /// (the program, the part, the height grid, the masks) and the
    /// oracle's mesh and its BVH, `ORACLE_BYTES_PER_TRIANGLE` per
    /// triangle (its copy of the heights and its per-pair buffers are
    /// small beside them). The item is by how much that phase passes the
    /// earlier ones (reading the part, the analysis): the whole stays the
    /// peak of the three.
    pub fn add_sample_check(&mut self, triangles: usize) {
        let before = self.bytes();
        let kept: f64 = self
            .items
            .iter()
            .filter(|(item, _)| KEPT_AFTER_THE_ENGINE.contains(item))
            .map(|(_, b)| b)
            .sum();
        let check = kept + ORACLE_BYTES_PER_TRIANGLE * triangles as f64;
        self.items.push(("sample check", (check - before).max(0.0)));
    }

    /// Makes the whole at least `reading` bytes, what reading the part
    /// held before this estimate's phase ([`MemoryEstimate::reading`]): the
    /// excess over the rest, where there is one, is an item of its own.
    pub fn cover_reading(&mut self, reading: f64) {
        let rest = self.bytes();
        if reading > rest {
            self.items.push((READING_BEYOND, reading - rest));
        }
    }

    /// The estimate of reading a part file of `file_bytes` bytes holding at
    /// most `triangles` triangles: the bytes, the reader's copy of them,
    /// the reader's triangles (f32, 48 bytes) and ours (f64, 72 bytes).
    pub fn reading(file_bytes: u64, triangles: u64) -> MemoryEstimate {
        MemoryEstimate {
            items: vec![
                ("program", BASE_BYTES),
                ("file", 2.0 * file_bytes as f64),
                ("triangles", (48.0 + BYTES_PER_TRIANGLE) * triangles as f64),
            ],
        }
    }

    /// The whole estimate (bytes).
    pub fn bytes(&self) -> f64 {
        self.items.iter().map(|(_, b)| b).sum()
    }

    /// The whole estimate (MiB).
    pub fn mib(&self) -> f64 {
        self.bytes() / MIB
    }
}

/// This process's peak resident memory so far (bytes), where the system
/// says (Linux's `/proc/self/status`, `VmHWM`).
pub fn peak_rss_bytes() -> Option<f64> {
    proc_field("/proc/self/status", "VmHWM:")
}

/// The machine's physical memory (bytes), where the system says
/// (`/proc/meminfo`, `MemTotal`).
pub(crate) fn physical_bytes() -> Option<f64> {
    proc_field("/proc/meminfo", "MemTotal:")
}

/// The memory this process may still take (bytes), and which limit sets
/// it, in words: the least of the machine's physical memory
/// ([`physical_bytes`]), the cgroup's limit (v2 `memory.max`, v1
/// `memory.limit_in_bytes`: a Slurm job's or a Kubernetes pod's) and the
/// address space `ulimit -v` leaves (`RLIMIT_AS` less what this process
/// has mapped already). `None` where the system says none of them.
pub(crate) fn limit_bytes() -> Option<(f64, &'static str)> {
    let mut limits: Vec<(f64, &'static str)> = Vec::new();
    if let Some(b) = physical_bytes() {
        limits.push((b, "this machine's memory"));
    }
    if let Some(b) = cgroup_limit_bytes() {
        limits.push((b, "the memory its cgroup allows (memory.max)"));
    }
    if let Some(b) = address_space_left_bytes() {
        limits.push((b, "the address space ulimit -v leaves"));
    }
    limits.into_iter().min_by(|a, b| a.0.total_cmp(&b.0))
}

/// Limits at or above this (bytes) are none (cgroup v1 writes its
/// "unlimited" as a page-rounded 2^63).
const NO_LIMIT_BYTES: f64 = (1u64 << 60) as f64;

/// This process's cgroup memory limit (bytes), v2 or v1, where one is set:
/// the least of its own cgroup's and every ancestor's up to the root
/// ([`cgroup_limit_under`] on this system's `/proc/self/cgroup` and
/// `/sys/fs/cgroup`).
fn cgroup_limit_bytes() -> Option<f64> {
    let own = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    cgroup_limit_under(std::path::Path::new("/sys/fs/cgroup"), &own)
}

/// The least memory limit (bytes) of the cgroup that `proc_cgroup` (the
/// text of `/proc/self/cgroup`) names and of each of its ancestors, under
/// the cgroup file system mounted at `root`: v2 (`0::/PATH`,
/// `root/PATH/memory.max`) and v1 (`N:...memory...:/PATH`,
/// `root/memory/PATH/memory.limit_in_bytes`). A Slurm job's or a
/// Kubernetes pod's limit is set on its own cgroup, not the root's; a
/// limit of a parent bounds its children too. `None` where no level sets
/// one.
pub(crate) fn cgroup_limit_under(root: &std::path::Path, proc_cgroup: &str) -> Option<f64> {
    let read = |path: &std::path::Path| {
        let text = crate::limits::read_bounded(path, 4096).ok()?;
        let value: f64 = std::str::from_utf8(&text).ok()?.trim().parse().ok()?;
        (value < NO_LIMIT_BYTES).then_some(value)
    };
    // Each level from the cgroup up to the root of `base`, `file` in each.
    let along = |base: std::path::PathBuf, cgroup: &str, file: &str| -> Vec<f64> {
        let mut dir = base.clone();
        dir.extend(
            cgroup
                .split('/')
                .filter(|c| !c.is_empty() && *c != "." && *c != ".."),
        );
        let mut limits = Vec::new();
        loop {
            limits.extend(read(&dir.join(file)));
            if dir == base || !dir.pop() {
                break;
            }
        }
        limits
    };
    let mut limits = Vec::new();
    for line in proc_cgroup.lines() {
        let mut fields = line.splitn(3, ':');
        let (Some(_id), Some(controllers), Some(path)) =
            (fields.next(), fields.next(), fields.next())
        else {
            continue;
        };
        if controllers.is_empty() {
            limits.extend(along(root.to_path_buf(), path, "memory.max"));
        } else if controllers.split(',').any(|c| c == "memory") {
            limits.extend(along(root.join("memory"), path, "memory.limit_in_bytes"));
        }
    }
    limits.into_iter().reduce(f64::min)
}

/// Whether this process can map `bytes` more now, found by asking for
/// them (`Vec::try_reserve_exact`, given back at once, no page touched):
/// `None` where it can, else about the most it can (bytes, to a MiB).
/// What the figures of [`limit_bytes`] miss refuses here before
/// any work, in a line, rather than in an abort part way: `ulimit -v` with
/// `/proc` unreadable, a strict overcommit policy (`vm.overcommit_memory`
/// 2), an address space already crowded.
pub(crate) fn unmappable(bytes: f64) -> Option<f64> {
    let fits = |b: f64| Vec::<u8>::new().try_reserve_exact(b as usize).is_ok();
    if !(bytes.is_finite() && bytes > 0.0) || fits(bytes) {
        return None;
    }
    let (mut lo, mut hi) = (0.0, bytes);
    while hi - lo > MIB {
        let mid = 0.5 * (lo + hi);
        if fits(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(lo)
}

/// Where this process could not start its work: the address space it
/// needs whatever the command (the program, `BASE_BYTES`, and an
/// allocator arena, `ARENA_BYTES`, for each thread it may start: one
/// per CPU and the progress ticker) and about the most the system gives
/// now (bytes, `unmappable`). Under a tight `ulimit -v` a command that
/// counts nothing else (`merge`, `report`) aborted on its first
/// allocation.
pub fn short_to_start() -> Option<(f64, f64)> {
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let need = BASE_BYTES + ARENA_BYTES * (cpus + 1) as f64;
    unmappable(need).map(|room| (need, room))
}

/// The address space glibc's allocator reserves for each thread's arena
/// (`HEAP_MAX_SIZE` on 64-bit Linux), mapped as the thread first
/// allocates: it counts in `ulimit -v`, though it is not memory used.
const ARENA_BYTES: f64 = 64.0 * MIB;

/// `RLIMIT_AS` (`ulimit -v`) less this process's mapped address space
/// (`VmSize`) and the arenas its threads may still map (one per worker
/// thread and one for the progress ticker, [`ARENA_BYTES`] each: without
/// them, runs that the check let through aborted on an allocation the
/// address space no longer held), where a limit is set (bytes).
fn address_space_left_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = text.lines().find(|l| l.starts_with("Max address space"))?;
    let soft: f64 = line
        .trim_start_matches("Max address space")
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let used = proc_field("/proc/self/status", "VmSize:").unwrap_or(0.0);
    let arenas = ARENA_BYTES * (rayon::current_num_threads() + 1) as f64;
    Some((soft - used - arenas).max(0.0))
}

/// A `/proc` line `KEY:   1234 kB` as bytes.
fn proc_field(file: &str, key: &str) -> Option<f64> {
    let text = std::fs::read_to_string(file).ok()?;
    let line = text.lines().find(|l| l.starts_with(key))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limit_is_at_most_the_machine_memory() {
        if cfg!(target_os = "linux") {
            let (limit, what) = limit_bytes().unwrap();
            assert!(limit <= physical_bytes().unwrap(), "{what}");
            assert!(limit > 0.0);
        }
    }

    /// Issue 41, item 6: in a child cgroup limited to 1.5 GiB under an
    /// unlimited root, the root's limit was read (none). A fake cgroup
    /// file system: the process's own cgroup's limit counts, and a
    /// parent's lower one bounds it, in v1 and v2 alike.
    #[test]
    fn the_limit_is_the_own_cgroups_and_its_ancestors() {
        let root = crate::output::temp_dir("cgroup");
        let write = |rel: &str, text: &str| {
            let path = root.join(rel);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, text).unwrap();
        };
        let gib = 1024.0 * 1024.0 * 1024.0;
        // v1: unlimited root, the job's 1.5 GiB.
        write("memory/memory.limit_in_bytes", "9223372036854771712\n");
        write(
            "memory/slurm/memory.limit_in_bytes",
            "9223372036854771712\n",
        );
        write("memory/slurm/job_7/memory.limit_in_bytes", "1610612736\n");
        let v1 = "12:cpuset:/slurm/job_7\n4:cpu,cpuacct,memory:/slurm/job_7\n";
        assert_eq!(cgroup_limit_under(&root, v1), Some(1.5 * gib));
        // A parent's lower limit bounds the job.
        write("memory/slurm/memory.limit_in_bytes", "1073741824\n");
        assert_eq!(cgroup_limit_under(&root, v1), Some(gib));
        // v2: max at the root, 3 GiB on the pod, 2 GiB on its parent.
        write("memory.max", "max\n");
        write("kubepods/memory.max", "2147483648\n");
        write("kubepods/pod1/memory.max", "3221225472\n");
        assert_eq!(
            cgroup_limit_under(&root, "0::/kubepods/pod1\n"),
            Some(2.0 * gib)
        );
        write("kubepods/memory.max", "max\n");
        assert_eq!(
            cgroup_limit_under(&root, "0::/kubepods/pod1\n"),
            Some(3.0 * gib)
        );
        // No limit anywhere, or no cgroup line.
        assert_eq!(cgroup_limit_under(&root, "0::/\n"), None);
        assert_eq!(cgroup_limit_under(&root, ""), None);
        std::fs::remove_dir_all(root).unwrap();
    }

    /// The sample check runs after the engine has freed its buffers: it
    /// raises the peak only where what the analysis keeps and the
    /// oracle's copy pass the analysis's (or the reading's) own peak.
    #[test]
    fn the_sample_check_is_a_phase_of_its_own() {
        let mib = MIB;
        let analysis = |engine: f64| MemoryEstimate {
            items: vec![
                ("program", 10.0 * mib),
                ("part", 72.0 * mib),
                ("height grid", 8.0 * mib),
                ("ranks", engine),
                ("masks", 2.0 * mib),
            ],
        };
        // A million triangles: the oracle's 400 MB pass an engine of 100
        // MiB; the peak is the check's, on what the analysis keeps.
        let mut big = analysis(100.0 * mib);
        big.add_sample_check(1_000_000);
        let kept = (10.0 + 72.0 + 8.0 + 2.0) * mib;
        assert_eq!(big.bytes(), kept + 4e8);
        // A thousand triangles: 0.4 MB of oracle beside a 100 MiB engine
        // raise no peak.
        let mut small = analysis(100.0 * mib);
        small.add_sample_check(1000);
        assert_eq!(small.bytes(), analysis(100.0 * mib).bytes());
        // Reading the part held more than either: the peak stays its.
        let mut read = analysis(0.0);
        read.cover_reading(2000.0 * mib);
        read.add_sample_check(1_000_000);
        assert_eq!(read.bytes(), 2000.0 * mib);
    }

    #[test]
    fn what_cannot_be_mapped_is_found_and_what_can_is_not() {
        assert_eq!(unmappable(MIB), None);
        // 2^60 bytes are beyond any address space of today (2^48 to 2^57).
        let huge = (1u64 << 60) as f64;
        let room = unmappable(huge).unwrap();
        assert!(room > MIB && room < huge, "{room}");
    }

    #[test]
    fn this_process_has_a_peak_and_the_machine_memory() {
        if cfg!(target_os = "linux") {
            assert!(peak_rss_bytes().unwrap() > 1e6);
            assert!(physical_bytes().unwrap() > peak_rss_bytes().unwrap());
        }
    }
}
