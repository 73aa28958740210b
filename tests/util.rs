//! Helpers shared by the integration tests: seeded random height grids and a
//! brute-force transcription of SPEC's push and slide that shares no code
//! with the engine (its own footprint geometry, its own ordering).

use kneeform::{GridSpec, HeightGrid, KneeForm};

/// The bundled scenario file `scenarios/NAME.toml`.
pub fn scenario_file(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenarios/{name}.toml"))
}

/// [`scenario_file`] as a command-line argument.
pub fn scenario(name: &str) -> String {
    scenario_file(name).display().to_string()
}

/// Asserts that a run of the binary succeeded, saying `what` and its
/// stderr where it did not; returns its output.
pub fn ok(out: std::process::Output, what: &str) -> std::process::Output {
    assert!(
        out.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The fixed seeds of every randomised test, in one place.
pub const SEEDS: [u64; 4] = [0x5eed_0001, 0x5eed_0002, 0xdead_beef, 42];

/// SplitMix64: tiny, seedable, good enough to draw test grids.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A random height grid: a tilt, a smooth undulation plus noise, heights
/// quantised to `quantum` mm, with holes (`+inf`) and a few blocks that
/// stand proud. At 0.5 mm exact ties (and exact-threshold differences)
/// occur; a finer quantum also makes the part gentle (tilt and undulation
/// scaled down, noise of a few um): rises of hundredths of a mm between
/// neighbours, rates on both sides of a deflection threshold of a
/// fraction of a degree.
pub fn random_grid_quantised(
    seed: u64,
    nx: usize,
    nz: usize,
    pitch: f64,
    quantum: f64,
) -> HeightGrid {
    let mut rng = Rng::new(seed);
    let spec = GridSpec {
        pitch,
        i_origin: (rng.next_u64() % 7) as i64 - 3,
        j_origin: (rng.next_u64() % 7) as i64 - 3,
        nx,
        nz,
    };
    let (fx, fz, amp) = (rng.unit() * 0.2, rng.unit() * 0.2, 2.0 + 10.0 * rng.unit());
    let hole = 0.03 + 0.1 * rng.unit();
    // A tilt towards the knee-form as it slides (-x): nodes in front stick
    // out further than the footprint's, so slides strike them.
    let tilt = 0.05 + 0.25 * rng.unit();
    let mut h = Vec::with_capacity(nx * nz);
    for j in 0..nz {
        for i in 0..nx {
            let (x, z) = (spec.x(i), spec.z(j));
            let (gentle, noise) = if quantum < 0.5 {
                (0.03, 0.004)
            } else {
                (1.0, 3.0)
            };
            let v =
                gentle * (amp * (fx * x).sin() * (fz * z).cos() + tilt * x) + noise * rng.unit();
            let v = if rng.unit() < 0.02 { v - 8.0 } else { v };
            h.push(if rng.unit() < hole {
                f64::INFINITY
            } else {
                (v / quantum).round() * quantum
            });
        }
    }
    HeightGrid { spec, h }
}

/// The rotated triangle of SPEC at `angle_deg`, as (x, z).
pub fn triangle(knee: &KneeForm, angle_deg: f64) -> [[f64; 2]; 3] {
    let t = angle_deg.to_radians();
    let l = knee.triangle_side;
    [
        [0.0, 0.0],
        [l * 3f64.sqrt() / 2.0, l / 2.0],
        [l * 3f64.sqrt() / 2.0, -l / 2.0],
    ]
    .map(|[x, z]| [x * t.cos() - z * t.sin(), x * t.sin() + z * t.cos()])
}

/// Distance from (x, z) to the filled triangle.
pub fn distance_to_triangle(v: &[[f64; 2]; 3], x: f64, z: f64) -> f64 {
    let cross = |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]) * (z - a[1]) - (b[1] - a[1]) * (x - a[0]);
    let s = [cross(v[0], v[1]), cross(v[1], v[2]), cross(v[2], v[0])];
    if s.iter().all(|&c| c >= 0.0) || s.iter().all(|&c| c <= 0.0) {
        return 0.0;
    }
    (0..3)
        .map(|k| {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            let (ex, ez) = (b[0] - a[0], b[1] - a[1]);
            let t = (((x - a[0]) * ex + (z - a[1]) * ez) / (ex * ex + ez * ez)).clamp(0.0, 1.0);
            (x - a[0] - t * ex).hypot(z - a[1] - t * ez)
        })
        .fold(f64::INFINITY, f64::min)
}

/// SPEC's closed-set tolerance (mm).
const TOL: f64 = 1e-9;

/// The left end `a(dz)` of the footprint's row, or `None` when the row
/// misses it: the footprint `T (+) D_R` is the union of the triangle, the
/// three discs at its corners and the three bands of half-width `R` along
/// its edges, and each meets the row in an interval found from its own
/// definition (independent of the engine's closed form). The discs' ends
/// are taken as `vx - sqrt((R - |dz - vz|)(R + |dz - vz|))`, exact where
/// the row is tangent to a disc: a distance test there (`distance <= R`)
/// is flat along the row and would place the end only within sqrt(ulp),
/// 2e-7 mm, which breaks SPEC's 1e-9 mm ties (measured: it did, at 30
/// degrees, where an edge runs along x and a row grazes its band).
pub fn row_start(v: &[[f64; 2]; 3], r: f64, dz: f64) -> Option<f64> {
    // Intervals of x where lo <= c0 + c1 x <= hi, intersected into `iv`.
    fn clip(iv: &mut (f64, f64), c0: f64, c1: f64, lo: f64, hi: f64) {
        if c1 == 0.0 {
            if !(lo..=hi).contains(&c0) {
                *iv = (f64::INFINITY, f64::NEG_INFINITY);
            }
            return;
        }
        let (x0, x1) = ((lo - c0) / c1, (hi - c0) / c1);
        let (x0, x1) = if x0 <= x1 { (x0, x1) } else { (x1, x0) };
        *iv = (iv.0.max(x0), iv.1.min(x1));
    }
    let all = (f64::NEG_INFINITY, f64::INFINITY);
    let mut left = f64::INFINITY;
    let mut keep = |iv: (f64, f64)| {
        if iv.0 <= iv.1 {
            left = left.min(iv.0);
        }
    };
    // The triangle: on the inner side of each edge (either orientation).
    let area2 =
        (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[1][1] - v[0][1]) * (v[2][0] - v[0][0]);
    let mut tri = all;
    for k in 0..3 {
        let (a, b) = (v[k], v[(k + 1) % 3]);
        // cross(b - a, P - a) * sign(area) >= 0, linear in x.
        let (ex, ez) = (b[0] - a[0], b[1] - a[1]);
        let sign = area2.signum();
        let c0 = sign * (ex * (dz - a[1]) + ez * a[0]);
        let c1 = sign * -ez;
        clip(&mut tri, c0, c1, 0.0, f64::INFINITY);
    }
    keep(tri);
    for k in 0..3 {
        // The band along edge a -> b: 0 <= (P - a).e <= |e|^2 and
        // |(P - a).n| <= R |e|, with n = (-ez, ex) (not normalised).
        let (a, b) = (v[k], v[(k + 1) % 3]);
        let (ex, ez) = (b[0] - a[0], b[1] - a[1]);
        let len2 = ex * ex + ez * ez;
        let mut band = all;
        clip(&mut band, -a[0] * ex + (dz - a[1]) * ez, ex, 0.0, len2);
        let rl = r * len2.sqrt();
        clip(&mut band, a[0] * ez + (dz - a[1]) * ex, -ez, -rl, rl);
        keep(band);
        // The disc at a.
        let off = (dz - a[1]).abs();
        if off <= r {
            let half = ((r - off) * (r + off)).sqrt();
            keep((a[0] - half, a[0] + half));
        }
    }
    left.is_finite().then_some(left)
}

/// A strike rule as the brute force takes it: the rounding tolerance `e0`
/// (mm), the deflection threshold `sigma` (a rate), and the deflection
/// window `W` (mm) of SPEC's window rule, `None` for the x-slope rule.
pub type BruteRule = (f64, f64, Option<f64>);

/// SPEC's push and slide, transcribed per start: every node's membership
/// from the distance to the footprint, every slide sorted in full, each
/// contact judged by SPEC's strike rule `rule`. Returns the colliding mask
/// and the number of placed starts.
pub fn brute_force(
    grid: &HeightGrid,
    knee: &KneeForm,
    angle_deg: f64,
    rule: BruteRule,
) -> (Vec<u8>, usize) {
    let (mut masks, placed) = brute_force_rules(grid, knee, angle_deg, &[rule]);
    (masks.remove(0), placed)
}

/// [`brute_force`] for several rules at once (the geometry is the costly
/// part): one mask per rule.
pub fn brute_force_rules(
    grid: &HeightGrid,
    knee: &KneeForm,
    angle_deg: f64,
    rules: &[BruteRule],
) -> (Vec<Vec<u8>>, usize) {
    let GridSpec {
        nx, nz, pitch: p, ..
    } = grid.spec;
    let v = triangle(knee, angle_deg);
    let r = knee.radius;
    let mut masks = vec![vec![0u8; nx * nz]; rules.len()];
    let mut placed = 0;
    for j0 in 0..nz {
        // Row starts per row offset, shared by the starts of this row.
        let rows: Vec<(usize, f64)> = (0..nz)
            .filter_map(|j| {
                let dz = (j as f64 - j0 as f64) * p;
                row_start(&v, r, dz).map(|a| (j, a))
            })
            .collect();
        for i0 in 0..nx {
            let mut yr = f64::INFINITY;
            let mut front: Vec<(f64, usize)> = Vec::new();
            for &(j, a) in &rows {
                let dz = (j as f64 - j0 as f64) * p;
                for i in 0..nx {
                    let dx = (i as f64 - i0 as f64) * p;
                    let node = j * nx + i;
                    if distance_to_triangle(&v, dx, dz) <= r + TOL {
                        yr = yr.min(grid.h[node]);
                    } else if dx < a {
                        front.push((a - dx, node));
                    }
                }
            }
            if yr == f64::INFINITY {
                continue;
            }
            placed += 1;
            front.sort_by(|x, y| x.0.total_cmp(&y.0));
            for (&(e0, sigma, window), mask) in rules.iter().zip(&mut masks) {
                let mut f = yr;
                // (travel, level after) of each group slid over so far.
                let mut after: Vec<(f64, f64)> = Vec::new();
                let mut k = 0;
                while k < front.len() {
                    let mut end = k + 1;
                    while end < front.len() && front[end].0 - front[end - 1].0 <= TOL {
                        end += 1;
                    }
                    // SPEC rule 2, window: the group's travel is its
                    // smallest distance; the level W back is the level
                    // after the last earlier group at most s - W + 1e-9
                    // away, the pushed level where there is none.
                    let s = front[k].0;
                    let back = window.map(|w| {
                        after
                            .iter()
                            .rev()
                            .find(|&&(t, _)| t <= s - w + TOL)
                            .map_or(yr, |&(_, level)| level)
                    });
                    let mut gmin = f64::INFINITY;
                    for &(_, node) in &front[k..end] {
                        let h = grid.h[node];
                        let deflected = match (window, back) {
                            (Some(w), Some(back)) => back - h > sigma * w,
                            _ => {
                                // SPEC rule 2, x-slope: the rise of the
                                // surface from the node one pitch behind
                                // (+x) in the same row; from the level
                                // where that node is off the part.
                                let i = node % nx;
                                let behind = if i + 1 < nx {
                                    grid.h[node + 1]
                                } else {
                                    f64::INFINITY
                                };
                                let x_slope = if behind.is_finite() {
                                    (behind - h) / p
                                } else {
                                    (f - h) / p
                                };
                                x_slope > sigma
                            }
                        };
                        if h < f - e0 && deflected {
                            mask[node] = 1;
                        }
                        gmin = gmin.min(h);
                    }
                    f = f.min(gmin);
                    after.push((s, f));
                    k = end;
                }
            }
        }
    }
    (masks, placed)
}

/// Renders a mask difference for an assertion message.
pub fn mask_diff(grid: &HeightGrid, got: &[u8], want: &[u8]) -> String {
    let nx = grid.spec.nx;
    let diffs: Vec<String> = got
        .iter()
        .zip(want)
        .enumerate()
        .filter(|(_, (g, w))| g != w)
        .take(10)
        .map(|(n, (g, w))| format!("(i={}, j={}): got {g} want {w}", n % nx, n / nx))
        .collect();
    format!(
        "{} differing nodes, first: {}",
        got.iter().zip(want).filter(|(g, w)| g != w).count(),
        diffs.join("; ")
    )
}

/// `kneeform analyze` of `triangles` (mm, analysis frame) at `pitch` and
/// `angles`, through the library: the grid and the masks.
pub fn analyse(
    triangles: &[kneeform::mesh::Triangle],
    pitch: f64,
    knee: &KneeForm,
    angles: &[f64],
) -> (HeightGrid, Vec<kneeform::AngleMask>) {
    use kneeform::{Analysis, Part, PartFile, Setup, Side};
    let part =
        Part::from_triangles("test", triangles.to_vec(), 1.0, Side::Left).expect("a valid part");
    let setup = Setup {
        pitch,
        knee: *knee,
        angles: angles.to_vec(),
        ..Setup::default()
    };
    let analysis =
        Analysis::run(PartFile::in_memory("test", part), &setup, &()).expect("an analysis");
    (analysis.grid, analysis.masks)
}

/// A unique, empty scratch directory under the system's temporary one.
pub fn scratch_dir(name: &str) -> std::path::PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "kneeform-test-{}-{}-{name}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a scratch directory");
    dir
}

/// A height-field part on the lattice `xs` x `zs` (sorted, mm), two
/// triangles per cell, surface facing -y ([`kneeform::scenario::tessellate`]
/// at `y(x, z)`): put lattice lines on a feature's edges to make it sharp.
pub fn lattice_part(
    xs: &[f64],
    zs: &[f64],
    y: impl Fn(f64, f64) -> f64,
) -> Vec<kneeform::mesh::Triangle> {
    kneeform::scenario::tessellate(xs, zs, |i, k| y(xs[i], zs[k]))
}

/// `from..=to` by `step`, plus the `extra` lines, sorted and deduplicated.
pub fn lines(from: f64, to: f64, step: f64, extra: &[f64]) -> Vec<f64> {
    let n = ((to - from) / step).round() as usize;
    let mut v: Vec<f64> = (0..=n)
        .map(|k| from + k as f64 * step)
        .chain(extra.iter().copied())
        .collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// Headless Chromium, when installed.
fn chromium() -> Option<std::path::PathBuf> {
    let path = std::env::var_os("PATH")?;
    ["chromium", "chromium-browser"].iter().find_map(|name| {
        std::env::split_paths(&path)
            .map(|d| d.join(name))
            .find(|p| p.is_file())
    })
}

/// Runs headless Chromium on the page `page` with `args` besides the
/// common ones (no sandbox, GPU or network, its profile in `dir`); its
/// output, or `None` (said on stderr, naming `check`) when Chromium is not
/// installed (CI installs it in .ci/run).
pub fn headless(
    page: &std::path::Path,
    dir: &std::path::Path,
    check: &str,
    args: &[String],
) -> Option<std::process::Output> {
    let Some(browser) = chromium() else {
        eprintln!("skipped the {check}: chromium not installed (CI installs it in .ci/run)");
        return None;
    };
    let out = std::process::Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            // WebGL on the CPU (SwiftShader): Chromium 15x turns it off
            // by default without a GPU, and the 3D view's tests need it.
            "--enable-unsafe-swiftshader",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
        ])
        .args(args)
        .arg(format!(
            "--user-data-dir={}",
            dir.join("chromium-profile").display()
        ))
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("chromium runs");
    Some(out)
}

/// Screenshots the page `page` in headless Chromium at 1200 x 1600, with
/// its profile and the shot in `dir`; the PNG's bytes, or `None` when
/// Chromium is not installed ([`headless`]).
pub fn screenshot(page: &std::path::Path, dir: &std::path::Path) -> Option<Vec<u8>> {
    let shot = dir.join("shot.png");
    let args = [
        "--hide-scrollbars".to_string(),
        "--window-size=1200,1600".to_string(),
        format!("--screenshot={}", shot.display()),
    ];
    let out = headless(page, dir, "browser check", &args)?;
    assert!(
        shot.is_file(),
        "no screenshot: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(std::fs::read(&shot).expect("the screenshot"))
}

/// Prints the page `page` to PDF in headless Chromium (A4, the page's
/// print stylesheet, no header or footer), with its profile and the PDF in
/// `dir`; the number of pages, or `None` when Chromium is not installed
/// ([`headless`]).
pub fn pdf_pages(page: &std::path::Path, dir: &std::path::Path) -> Option<usize> {
    let pdf = dir.join("page.pdf");
    let args = [
        "--no-pdf-header-footer".to_string(),
        format!("--print-to-pdf={}", pdf.display()),
    ];
    let out = headless(page, dir, "print check", &args)?;
    let bytes = std::fs::read(&pdf).unwrap_or_else(|_| {
        panic!("no PDF: {}", String::from_utf8_lossy(&out.stderr));
    });
    // Each page is one object of type /Page (the page tree's are /Pages).
    let text = String::from_utf8_lossy(&bytes);
    let pages = text
        .match_indices("/Type /Page")
        .filter(|(at, m)| !text[at + m.len()..].starts_with('s'))
        .count();
    assert!(pages > 0, "no page objects in the PDF");
    Some(pages)
}

/// How wide the page `page` lays out on a screen `width` px wide, and
/// that width (px), measured in headless Chromium: the document's
/// `scrollWidth` beyond the window's is a horizontal scrollbar the reader
/// must use. `None` when Chromium is not installed ([`headless`]).
pub fn screen_width(
    page: &std::path::Path,
    dir: &std::path::Path,
    width: u32,
) -> Option<(u32, u32)> {
    let html = std::fs::read_to_string(page).expect("the page");
    let script = "<script>
addEventListener('load', () => {
  const out = document.createElement('pre');
  out.id = 'screen-width';
  out.textContent = 'measured ' + document.documentElement.scrollWidth + ' ' + window.innerWidth;
  document.body.appendChild(out);
});
</script>";
    let flags = [
        "--hide-scrollbars".to_string(),
        format!("--window-size={width},1600"),
    ];
    let text = probe(
        &html,
        script,
        (dir, "screen-probe.html", "screen width check"),
        "screen-width",
        &flags,
    )?;
    let mut numbers = text
        .split_whitespace()
        .map(|n| n.parse::<u32>().expect("a width"));
    Some((numbers.next().unwrap(), numbers.next().unwrap()))
}

/// The page `html` with `head` added to its head, written to `name` in
/// `dir` and loaded in headless Chromium (`flags` beside the virtual time
/// and the DOM dump; `what` names the check): the text its script wrote
/// after `measured` into `<pre id="ID">`, `ID` being `id`. `None` when
/// Chromium is not installed ([`headless`]).
fn probe(
    html: &str,
    head: &str,
    (dir, name, what): (&std::path::Path, &str, &str),
    id: &str,
    flags: &[String],
) -> Option<String> {
    let page = html.replacen("</head>", &format!("{head}</head>"), 1);
    let path = dir.join(name);
    std::fs::write(&path, page).unwrap();
    let mut args = flags.to_vec();
    args.extend([
        "--virtual-time-budget=5000".to_string(),
        "--dump-dom".to_string(),
    ]);
    let out = headless(&path, dir, what, &args)?;
    let dom = String::from_utf8_lossy(&out.stdout);
    let marker = format!("<pre id=\"{id}\">measured");
    let start = dom.find(&marker).unwrap_or_else(|| {
        panic!(
            "the probe did not run: {}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let rest = &dom[start + marker.len()..];
    Some(rest[..rest.find("</pre>").expect("the probe's end")].to_string())
}

/// The tables of the page `page` wider than the printed page: the page's
/// print stylesheet applied on screen (`@media print` read as `@media
/// all`) with the body as wide as an A4 portrait page's text (186 mm:
/// 210 mm less the 12 mm margins), each table measured in headless
/// Chromium. Each overflowing table as `class#id: width/body px`; `None`
/// when Chromium is not installed ([`headless`]).
pub fn tables_wider_than_print(
    page: &std::path::Path,
    dir: &std::path::Path,
) -> Option<Vec<String>> {
    let html = std::fs::read_to_string(page).expect("the page");
    assert!(
        html.contains("@media print"),
        "the page has no print stylesheet"
    );
    // The screen-only rules off: they would hold a wide table in a box of
    // its own, hiding what print lays out.
    let html = html
        .replace("@media print", "@media all")
        .replace("@media screen", "@media not all");
    let head = "<style>body { width: 186mm !important; max-width: none !important; }</style>
<script>
addEventListener('load', () => {
  const body = document.body.getBoundingClientRect();
  const over = [];
  document.querySelectorAll('table').forEach((t, k) => {
    const r = t.getBoundingClientRect();
    if (r.right > body.right + 1) {
      over.push((t.className || 'table') + '#' + (t.id || k) + ': ' + Math.round(r.width) + '/' + Math.round(body.width) + ' px');
    }
  });
  const out = document.createElement('pre');
  out.id = 'print-overflow';
  out.textContent = 'measured\\n' + over.join('\\n');
  document.body.appendChild(out);
});
</script>";
    let text = probe(
        &html,
        head,
        (dir, "print-probe.html", "print width check"),
        "print-overflow",
        &[],
    )?;
    Some(text.lines().skip(1).map(str::to_string).collect())
}

/// A decoded RGB(A) image.
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub channels: usize,
    pub pixels: Vec<u8>,
}

impl Image {
    pub fn decode(bytes: &[u8]) -> Image {
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder.read_info().expect("a PNG");
        let mut pixels = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut pixels).expect("a frame");
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        let channels = match info.color_type {
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            other => panic!("unexpected colour type {other:?}"),
        };
        pixels.truncate(info.buffer_size());
        Image {
            width: info.width as usize,
            height: info.height as usize,
            channels,
            pixels,
        }
    }

    pub fn at(&self, c: usize, r: usize) -> [u8; 3] {
        let k = self.channels * (r * self.width + c);
        [self.pixels[k], self.pixels[k + 1], self.pixels[k + 2]]
    }

    /// Every pixel's RGB, row by row from the top.
    pub fn rgb(&self) -> Vec<[u8; 3]> {
        self.pixels
            .chunks(self.channels)
            .map(|c| [c[0], c[1], c[2]])
            .collect()
    }
}

/// A point the surface level evaluates: its value (mm) and where it is
/// (grid units).
type Sample = (f64, [f64; 2]);

/// SPEC v4's surface `S` at `(u, w)` in grid units: each closed cell split
/// along its `(i, j)-(i+1, j+1)` diagonal, `+inf` off the grid or where a
/// corner is infinite; a point on the last column or row in the cell
/// before it.
fn surface_at(grid: &HeightGrid, u: f64, w: f64) -> f64 {
    let (nx, nz) = (grid.spec.nx, grid.spec.nz);
    if nx < 2 || nz < 2 || !(u >= 0.0 && w >= 0.0) || u > (nx - 1) as f64 || w > (nz - 1) as f64 {
        return f64::INFINITY;
    }
    let (i, j) = (
        (u.floor() as usize).min(nx - 2),
        (w.floor() as usize).min(nz - 2),
    );
    let (fx, fz) = (u - i as f64, w - j as f64);
    let h = |a: usize, b: usize| grid.h[(j + b) * nx + i + a];
    let (h00, h10, h01, h11) = (h(0, 0), h(1, 0), h(0, 1), h(1, 1));
    if [h00, h10, h01, h11].iter().any(|v| !v.is_finite()) {
        return f64::INFINITY;
    }
    if fx >= fz {
        h00 + fx * (h10 - h00) + fz * (h11 - h10)
    } else {
        h00 + fz * (h01 - h00) + fx * (h11 - h01)
    }
}

/// SPEC v4's tie tolerance at the cell holding `(u, w)`: a quarter of the
/// largest second difference centred on one of its corners (x, z and
/// both diagonals, finite ones), capped at a quarter pitch.
fn surface_tau(grid: &HeightGrid, u: f64, w: f64) -> f64 {
    let (nx, nz) = (grid.spec.nx as i64, grid.spec.nz as i64);
    if nx < 2 || nz < 2 || !(u >= 0.0 && w >= 0.0) || u > (nx - 1) as f64 || w > (nz - 1) as f64 {
        return 0.0;
    }
    let (i, j) = (
        (u.floor() as i64).min(nx - 2),
        (w.floor() as i64).min(nz - 2),
    );
    let h = |a: i64, b: i64| {
        if (0..nx).contains(&a) && (0..nz).contains(&b) {
            grid.h[(b * nx + a) as usize]
        } else {
            f64::INFINITY
        }
    };
    let mut most = 0.0f64;
    for (ci, cj) in [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)] {
        for (di, dj) in [(1, 0), (0, 1), (1, 1), (1, -1)] {
            let d = h(ci - di, cj - dj) - 2.0 * h(ci, cj) + h(ci + di, cj + dj);
            if d.is_finite() {
                most = most.max(d.abs());
            }
        }
    }
    (most / 4.0).min(0.25 * grid.spec.pitch)
}

/// The knee-form's outline at `angle_deg` as SPEC v4 samples it, in
/// pitches from the reference point, `(leading, trailing)`, each by
/// increasing z: the bottom, every quarter pitch (the rows exactly), the
/// top, and midpoints in z wherever two samples lie more than a quarter
/// pitch apart. The outline's ends are the library's `row_interval`: the
/// samples' positions are the contract's, to the bit.
pub fn surface_outline(knee: &KneeForm, angle_deg: f64, p: f64) -> [Vec<[f64; 2]>; 2] {
    let shape = kneeform::Footprint::new(knee, angle_deg);
    let (z_lo, z_hi) = shape.z_range();
    let mut dws = vec![z_lo / p];
    let (m_lo, m_hi) = (
        (z_lo / p / 0.25).ceil() as i64,
        (z_hi / p / 0.25).floor() as i64,
    );
    for m in m_lo..=m_hi {
        dws.push(if m % 4 == 0 {
            (m / 4) as f64
        } else {
            m as f64 * 0.25
        });
    }
    dws.push(z_hi / p);
    dws.dedup();
    let side = |leading: bool| {
        let at = |dw: f64| {
            shape
                .row_interval(dw * p)
                .map(|(a, b)| [if leading { a } else { b } / p, dw])
        };
        fn fill(
            at: &dyn Fn(f64) -> Option<[f64; 2]>,
            a: [f64; 2],
            b: [f64; 2],
            out: &mut Vec<[f64; 2]>,
            depth: u32,
        ) {
            if (a[0] - b[0]).hypot(a[1] - b[1]) <= 0.25 || depth >= 20 {
                return;
            }
            if let Some(mid) = at((a[1] + b[1]) / 2.0) {
                fill(at, a, mid, out, depth + 1);
                out.push(mid);
                fill(at, mid, b, out, depth + 1);
            }
        }
        let mut out: Vec<[f64; 2]> = Vec::new();
        for &dw in &dws {
            if let Some(here) = at(dw) {
                if let Some(&before) = out.last() {
                    fill(&at, before, here, &mut out, 0);
                }
                out.push(here);
            }
        }
        out
    };
    [side(true), side(false)]
}

/// SPEC v4's surface level, per start, evaluating everything (no bound,
/// no early end): the push over the whole outline and the nodes inside;
/// steps of `p / 8` over the leading outline and the nodes met (a fall
/// of more than `e0` a contact, a smaller one leaving the level); the
/// bisection between witnesses more than `p / 2` apart; the tie set
/// (every outline point within the witness's cell's `tau` of the level,
/// each judged by the window rule on its own value); the window rule on
/// the level curve; the node nearest each struck witness.
/// The readings where SPEC leaves a choice are `kneeform`'s
/// (`src/surface.rs`'s module comment). Returns the mask and the number
/// of placed starts.
pub fn brute_force_surface(
    grid: &HeightGrid,
    knee: &KneeForm,
    angle_deg: f64,
    (e0, sigma, window): (f64, f64, f64),
) -> (Vec<u8>, usize) {
    let GridSpec {
        nx, nz, pitch: p, ..
    } = grid.spec;
    let v = triangle(knee, angle_deg);
    let r = knee.radius;
    let [lead, trail] = surface_outline(knee, angle_deg, p);
    let du_max = lead.iter().map(|s| s[0]).fold(f64::NEG_INFINITY, f64::max);
    let mut mask = vec![0u8; nx * nz];
    let mut placed = 0;
    let nearest = |at: [f64; 2]| {
        let (i, j) = ((at[0] - 0.5).ceil() as usize, (at[1] - 0.5).ceil() as usize);
        j * nx + i
    };
    // The first lowest of `points` (value, where) below `limit`.
    let lowest = |points: &mut dyn Iterator<Item = Sample>, limit: f64| {
        let mut best: Option<Sample> = None;
        for (value, at) in points {
            if value < limit && best.is_none_or(|b| value < b.0) {
                best = Some((value, at));
            }
        }
        best
    };
    let outline_at = |t: f64, i0: usize, j0: usize| -> Vec<Sample> {
        let base = i0 as f64 - t / 8.0;
        lead.iter()
            .map(|&[du, dw]| {
                let at = [base + du, j0 as f64 + dw];
                (surface_at(grid, at[0], at[1]), at)
            })
            .collect()
    };
    for j0 in 0..nz {
        for i0 in 0..nx {
            // The nodes inside and in front, rows by j, each row's nodes
            // in front by distance.
            let mut inside: Vec<Sample> = Vec::new();
            let mut front: Vec<(f64, f64, [f64; 2])> = Vec::new();
            for j in 0..nz {
                let dz = (j as f64 - j0 as f64) * p;
                let Some(a) = row_start(&v, r, dz) else {
                    continue;
                };
                let mut row: Vec<(f64, f64, [f64; 2])> = Vec::new();
                for i in 0..nx {
                    let dx = (i as f64 - i0 as f64) * p;
                    let h = grid.h[j * nx + i];
                    if distance_to_triangle(&v, dx, dz) <= r + TOL {
                        inside.push((h, [i as f64, j as f64]));
                    } else if dx < a {
                        row.push((a - dx, h, [i as f64, j as f64]));
                    }
                }
                row.sort_by(|x, y| x.0.total_cmp(&y.0));
                front.extend(row);
            }
            let mut push: Vec<Sample> = outline_at(0.0, i0, j0);
            let base = i0 as f64;
            push.extend(trail.iter().map(|&[du, dw]| {
                let at = [base + du, j0 as f64 + dw];
                (surface_at(grid, at[0], at[1]), at)
            }));
            push.extend(inside);
            let Some((yr, pushed_at)) = lowest(&mut push.into_iter(), f64::INFINITY) else {
                continue;
            };
            placed += 1;
            let mut f = yr;
            let mut witness = pushed_at;
            // (travel, level after) at each fall.
            let mut after: Vec<(f64, f64)> = Vec::new();
            // A fall to `value` at travel `t` steps, its witness `at`, the
            // outline's points there `points`.
            let mut fall = |t: f64,
                            value: f64,
                            at: [f64; 2],
                            points: &[Sample],
                            f: &mut f64,
                            witness: &mut [f64; 2]| {
                // Only a contact moves the level: a fall of at most e0
                // is rounding.
                if value >= *f - e0 {
                    return;
                }
                let s = t * p / 8.0;
                let back = after
                    .iter()
                    .rev()
                    .find(|&&(u, _)| u <= s - window + TOL)
                    .map_or(yr, |&(_, level)| level);
                if back - value > sigma * window {
                    mask[nearest(at)] = 1;
                    // The tie set: every outline point within the
                    // witness's cell's tau of the new level, each judged
                    // by the window rule on its own value.
                    let tau = surface_tau(grid, at[0], at[1]);
                    for &(pv, pat) in points {
                        if pv <= value + tau && back - pv > sigma * window {
                            mask[nearest(pat)] = 1;
                        }
                    }
                }
                *witness = at;
                *f = value;
                after.push((s, value));
            };
            let apart = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) > 0.5;
            front.sort_by(|x, y| x.0.total_cmp(&y.0));
            let mut cursor = 0;
            let mut k = 0u64;
            loop {
                k += 1;
                let t = k as f64;
                let s = t * p / 8.0;
                if base - t / 8.0 + du_max < 0.0 && cursor == front.len() {
                    break;
                }
                let points = outline_at(t, i0, j0);
                let mut here: Vec<Sample> = points.clone();
                // The nodes met by this step, rows by j, each by distance.
                let first = cursor;
                while cursor < front.len() && front[cursor].0 <= s + TOL {
                    cursor += 1;
                }
                let mut met = front[first..cursor].to_vec();
                met.sort_by(|x, y| x.2[1].total_cmp(&y.2[1]).then(x.0.total_cmp(&y.0)));
                here.extend(met.iter().map(|n| (n.1, n.2)));
                let Some((value, at)) = lowest(&mut here.into_iter(), f64::INFINITY) else {
                    continue;
                };
                if value < f - e0 && apart(witness, at) {
                    // Bisection, midpoints applied in travel order.
                    let (f0, w_lo) = (f, witness);
                    fn halves(
                        (lo, hi): (f64, f64),
                        (w_lo, w_hi): ([f64; 2], [f64; 2]),
                        depth: u32,
                        eval: &mut dyn FnMut(f64) -> (Vec<Sample>, Option<Sample>),
                        apply: &mut dyn FnMut(f64, Sample, &[Sample]),
                    ) {
                        if depth >= 5 || (w_lo[0] - w_hi[0]).hypot(w_lo[1] - w_hi[1]) <= 0.5 {
                            return;
                        }
                        let mid = (lo + hi) / 2.0;
                        let (points, low) = eval(mid);
                        let w_mid = low.map_or(w_lo, |l| l.1);
                        halves((lo, mid), (w_lo, w_mid), depth + 1, eval, apply);
                        if let Some(low) = low {
                            apply(mid, low, &points);
                        }
                        halves((mid, hi), (w_mid, w_hi), depth + 1, eval, apply);
                    }
                    let mut eval = |mid: f64| {
                        let points = outline_at(mid, i0, j0);
                        let low = lowest(&mut points.clone().into_iter(), f0 - e0);
                        (points, low)
                    };
                    let mut apply = |mid: f64, (value, at): Sample, pts: &[Sample]| {
                        fall(mid, value, at, pts, &mut f, &mut witness);
                    };
                    halves((t - 1.0, t), (w_lo, at), 0, &mut eval, &mut apply);
                }
                fall(t, value, at, &points, &mut f, &mut witness);
            }
        }
    }
    (mask, placed)
}
