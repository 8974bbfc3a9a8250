//! Shared checks of the binary readers' tests: a real file of `shared/topographies` read to
//! the reference that SurfaceTopography 1.27.1 made of it, and the robustness loop that every
//! reader must survive (truncations, header bytes flipped at random, a wrong signature).

use super::{Heights, Reading};
use crate::Result;
use ndarray::Array2;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// SurfaceTopography's reading of one file.
pub(crate) struct Reference {
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// The reference heights in metres, indexed `[x, y]` as SurfaceTopography gives them.
    pub heights_xy: Array2<f64>,
    /// The channel names, in file order.
    pub channels: Vec<String>,
    /// The name of the default channel.
    pub default_channel: String,
    /// Physical sizes `[x, y]` in metres.
    pub size_m: [f64; 2],
    /// The file's own height unit.
    pub unit: String,
    /// The number of undefined points.
    pub undefined: usize,
}

/// The file `name` and its reference, or `None` (with a notice) where the folder is absent.
pub(crate) fn reference(name: &str) -> Option<Reference> {
    let dir = set_dir("topographies")?;
    let bytes = std::fs::read(dir.join(name)).expect("reading the shared file");
    let heights_xy: Array2<f64> =
        ndarray_npy::read_npy(dir.join(format!("{name}.reference.npy"))).expect("reference npy");
    let json = std::fs::read_to_string(dir.join(format!("{name}.reference.json"))).unwrap();
    let meta: serde_json::Value = serde_json::from_str(&json).unwrap();
    let text = |v: &serde_json::Value| v.as_str().unwrap().to_string();
    Some(Reference {
        bytes,
        heights_xy,
        channels: meta["channels"]
            .as_array()
            .unwrap()
            .iter()
            .map(text)
            .collect(),
        default_channel: text(&meta["default_channel"]),
        size_m: [
            meta["physical_sizes_m"][0].as_f64().unwrap(),
            meta["physical_sizes_m"][1].as_f64().unwrap(),
        ],
        unit: text(&meta["unit"]),
        undefined: meta["undefined_points"].as_u64().unwrap() as usize,
    })
}

/// Checks a reading against the reference: channel names and count, the default channel's
/// sizes (1e-12 relative), its unit, its undefined points (same places) and every height
/// to 1e-12 relative (both are the file's numbers times the same factors; the largest
/// difference measured is 2.2e-16, the rounding of a different order of products).
/// `expected` is the reference heights already mapped to our `(row, col) = (y, x)` order
/// (the caller states the mapping, a transpose and the flips the peer applies).
pub(crate) fn assert_matches(reading: &Reading, r: &Reference, expected: &Array2<f64>) {
    let names: Vec<&str> = reading.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, r.channels, "channel names");
    let default = reading
        .channels
        .iter()
        .find(|c| c.is_height)
        .expect("a height channel");
    assert_eq!(default.name, r.default_channel, "default channel");
    assert_eq!(default.unit.as_deref(), Some(r.unit.as_str()), "unit");
    for (axis, want) in r.size_m.iter().enumerate() {
        let got = default.size[axis].expect("a size");
        assert!(
            (got - want).abs() <= 1e-12 * want.abs(),
            "size[{axis}] {got} vs {want}"
        );
    }
    let Heights::Areal(h) = &default.heights else {
        panic!("an areal channel expected")
    };
    assert_eq!(h.dim(), expected.dim(), "grid (rows, cols)");
    let mut undefined = 0;
    for ((idx, got), want) in h.indexed_iter().zip(expected.iter()) {
        if want.is_nan() {
            undefined += 1;
            assert!(
                got.is_nan(),
                "{idx:?}: {got} where the reference is undefined"
            );
        } else {
            assert!(
                (got - want).abs() <= 1e-12 * want.abs(),
                "{idx:?}: {got} vs reference {want}"
            );
        }
    }
    assert_eq!(undefined, r.undefined, "undefined points of the reference");
}

/// A tiny deterministic generator (xorshift64*), so the loop needs no seeded crate state.
struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// A reader's entry points, for the robustness loop.
pub(crate) type ReadFn = fn(&[u8]) -> Result<Reading>;

/// What any reading must satisfy: at least one channel and no more points than the file has
/// bytes (so a corrupt size could not have been allocated from).
fn assert_bounded(reading: &Reading, file_len: usize) {
    assert!(!reading.channels.is_empty());
    let points: usize = reading
        .channels
        .iter()
        .map(|c| match &c.heights {
            Heights::Areal(a) => a.len(),
            Heights::Profile(p) => p.len(),
        })
        .sum();
    assert!(points <= file_len, "{points} points from {file_len} bytes");
}

/// The robustness loop: the intact file is recognised; every truncation tried is an error
/// (lengths at a stride of about 1/400 of the first `header` bytes, and 64 spread over the
/// rest); flipping 1–4 random bits of the first `header` bytes (seeded, for about `budget`)
/// never panics and never gives more points than bytes; and, where `magic` is given, a file
/// whose first `magic` bytes are changed is neither recognised nor read.
pub(crate) fn assert_robust(
    bytes: &[u8],
    sniff: fn(&[u8]) -> bool,
    read: ReadFn,
    header: usize,
    magic: Option<usize>,
    budget: Duration,
) {
    assert!(sniff(bytes), "the intact file is recognised");
    let len = bytes.len();
    let header = header.min(len);
    let stride = (header / 400).max(1);
    let spread = (0..64).map(|k| header + (len - header) * k / 64);
    for cut in (0..header).step_by(stride).chain(spread).chain([len - 1]) {
        assert!(
            read(&bytes[..cut]).is_err(),
            "a file cut to {cut} of {len} bytes was read"
        );
    }
    if let Some(m) = magic {
        let mut wrong = bytes.to_vec();
        for b in &mut wrong[..m] {
            *b = b.wrapping_add(0x5a);
        }
        assert!(!sniff(&wrong), "a wrong signature is not recognised");
        assert!(read(&wrong).is_err(), "a wrong signature is refused");
    }
    let (budget, max_tries) = fuzz_budget(budget);
    let mut work = bytes.to_vec();
    let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
    let start = Instant::now();
    let mut tries = 0;
    while start.elapsed() < budget && tries < max_tries {
        tries += 1;
        let flips: Vec<usize> = (0..1 + rng.below(4)).map(|_| rng.below(header)).collect();
        for &i in &flips {
            work[i] ^= 1 << rng.below(8);
        }
        if let Ok(reading) = read(&work) {
            assert_bounded(&reading, len);
        }
        for &i in &flips {
            work[i] = bytes[i];
        }
    }
    assert!(tries > 0);
    eprintln!("{tries} corrupted headers read without a panic");
}

/// The time and the most tries of a fuzz loop given `budget`: `ASPERITY_FUZZ_MS`
/// (milliseconds) replaces the budget, for a longer run by hand; see [`budget_from`].
pub(crate) fn fuzz_budget(budget: Duration) -> (Duration, usize) {
    budget_from(std::env::var("ASPERITY_FUZZ_MS").ok().as_deref(), budget)
}

/// The budget (`ms`, when it is a number of milliseconds, else `budget`) and the most
/// tries: 20 000 within a second, no cap beyond (a run by hand lasts its time).
fn budget_from(ms: Option<&str>, budget: Duration) -> (Duration, usize) {
    let budget = ms
        .and_then(|v| v.trim().parse().ok())
        .map_or(budget, Duration::from_millis);
    let tries = if budget > Duration::from_secs(1) {
        usize::MAX
    } else {
        20_000
    };
    (budget, tries)
}

#[test]
fn every_fuzz_loop_takes_its_time_from_asperity_fuzz_ms() {
    let short = Duration::from_millis(300);
    assert_eq!(budget_from(None, short), (short, 20_000));
    assert_eq!(budget_from(Some("nonsense"), short), (short, 20_000));
    assert_eq!(
        budget_from(Some("60000"), short),
        (Duration::from_secs(60), usize::MAX)
    );
    assert_eq!(
        budget_from(Some("10"), short),
        (Duration::from_millis(10), 20_000)
    );
}

/// The offsets of the size fields of every zip header in `bytes`: the compressed and
/// uncompressed sizes of each local file header (`PK\x03\x04`, at +18 and +22) and each
/// central directory header (`PK\x01\x02`, at +20 and +24), as `(offset, uncompressed)`.
fn zip_size_fields(bytes: &[u8]) -> Vec<(usize, bool)> {
    let mut fields = Vec::new();
    for i in 0..bytes.len().saturating_sub(46) {
        if bytes[i..].starts_with(b"PK\x03\x04") {
            fields.extend([(i + 18, false), (i + 22, true)]);
        } else if bytes[i..].starts_with(b"PK\x01\x02") {
            fields.extend([(i + 20, false), (i + 24, true)]);
        }
    }
    fields
}

/// The zip-bomb loop of a zip-based format: every member made to declare 4 GiB (in its
/// local and central headers) is refused in one line or, where the reader does not open
/// that member, changes nothing; then, for about `budget`, one to
/// three size fields at a time are set to sizes a hostile file would hold (0, 1, a little
/// more or less than the true size, 2³¹, 4 GiB − 1, the zip64 marker, random), which
/// must never panic nor read more points than the file has bytes. Prints how many
/// archives were tried and how many were refused.
pub(crate) fn assert_zip_sizes_robust(bytes: &[u8], read: ReadFn, budget: Duration) {
    let fields = zip_size_fields(bytes);
    assert!(!fields.is_empty(), "no zip headers found");
    let le = |b: &[u8], at: usize| u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
    let locals: Vec<usize> = (0..fields.len()).filter(|&k| fields[k].1).collect();
    for &k in &locals {
        // This member's local and central uncompressed sizes (the central entry names the
        // same member when it holds the same size).
        let mut bomb = bytes.to_vec();
        let size = le(bytes, fields[k].0);
        for &(at, uncompressed) in &fields {
            if uncompressed && le(bytes, at) == size {
                bomb[at..at + 4].copy_from_slice(&(u32::MAX - 1).to_le_bytes());
            }
        }
        // Refused in one line, or (a member the reader does not open) read unchanged.
        match read(&bomb) {
            Err(e) => assert_eq!(e.to_string().lines().count(), 1, "{e}"),
            Ok(r) => assert_eq!(
                format!("{r:?}"),
                format!("{:?}", read(bytes).unwrap()),
                "a member declaring 4 GiB changed the reading"
            ),
        }
    }
    let mut rng = XorShift(0x2545_f491_4f6c_dd1d);
    let (budget, max_tries) = fuzz_budget(budget);
    let (start, mut tries, mut refused) = (Instant::now(), 0usize, 0usize);
    let mut work = bytes.to_vec();
    while start.elapsed() < budget && tries < max_tries {
        tries += 1;
        let picked: Vec<usize> = (0..1 + rng.below(3))
            .map(|_| rng.below(fields.len()))
            .collect();
        for &k in &picked {
            let at = fields[k].0;
            let true_size = le(bytes, at);
            let value = match rng.below(8) {
                0 => 0,
                1 => 1,
                2 => true_size.wrapping_add(1 + rng.below(64) as u32),
                3 => true_size.saturating_sub(1 + rng.below(64) as u32),
                4 => 1 << 31,
                5 => u32::MAX - 1,
                6 => u32::MAX,
                _ => rng.next() as u32,
            };
            work[at..at + 4].copy_from_slice(&value.to_le_bytes());
        }
        match read(&work) {
            Ok(reading) => assert_bounded(&reading, bytes.len()),
            Err(e) => {
                refused += 1;
                assert_eq!(e.to_string().lines().count(), 1, "{e}");
            }
        }
        for &k in &picked {
            let at = fields[k].0;
            work[at..at + 4].copy_from_slice(&bytes[at..at + 4]);
        }
    }
    assert!(tries > 0);
    eprintln!("{tries} archives with altered zip sizes read without a panic ({refused} refused)");
}

/// The reference's `[x, y]` heights as our `(row, col) = (y, x)` map: the transpose.
pub(crate) fn transposed(r: &Reference) -> Array2<f64> {
    r.heights_xy.t().as_standard_layout().into_owned()
}

/// Element-wise equality to 1e-12 relative (both NaN counts as equal), for the synthetic
/// files whose expected values are written as decimal products.
pub(crate) fn assert_close<'a>(got: impl IntoIterator<Item = &'a f64>, want: &[f64]) {
    let got: Vec<f64> = got.into_iter().copied().collect();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        let same = (g.is_nan() && w.is_nan()) || (g - w).abs() <= 1e-12 * w.abs();
        assert!(same, "{got:?} vs {want:?}");
    }
}

/// `shared/<set>` (`topographies`, `topographies-2`, `topographies-3`): beside the
/// repository (CI), beside the folder of worktrees (development checkouts one level
/// deeper), or beside `$ASPERITY_TOPOGRAPHIES` where it is set (it names
/// `shared/topographies`). `None` with a notice where the folder is absent; under CI, which
/// has the shared files beside the repository, a failure instead: a skip would hide a gap.
pub(crate) fn set_dir(set: &str) -> Option<PathBuf> {
    let roots: Vec<PathBuf> = match std::env::var_os("ASPERITY_TOPOGRAPHIES") {
        Some(dir) => PathBuf::from(dir)
            .parent()
            .map(PathBuf::from)
            .into_iter()
            .collect(),
        None => vec![
            PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared")),
            PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../../shared")),
        ],
    };
    if let Some(dir) = roots.iter().map(|r| r.join(set)).find(|d| d.is_dir()) {
        return Some(dir);
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "shared/{set} not found beside the repository, and CI needs it"
    );
    eprintln!("shared/{set} not found beside the repository: skipping");
    None
}

/// What a file of a further shared set is expected to read as, beyond the reference's
/// heights: the deliberate differences are stated by the caller.
pub(crate) struct Expect {
    /// Compare the list of channel names with the reference's.
    pub channel_names: bool,
    /// The unit our reader gives (`None`: the file gives none), where it differs on purpose
    /// from the reference's; `Some(None)` keeps the reference's.
    pub unit: Option<Option<&'static str>>,
    /// Our heights are the reference's times this factor (a unit the peer ignores).
    pub height_factor: f64,
    /// Our sizes `[x, y]` in metres where the reference has none or differs on purpose.
    pub size: Option<[Option<f64>; 2]>,
}

impl Default for Expect {
    fn default() -> Self {
        Expect {
            channel_names: true,
            unit: None,
            height_factor: 1.0,
            size: None,
        }
    }
}

/// Reads `shared/<set>/<name>` as `read_file` would (detection by content, then
/// extension) and checks the default channel against SurfaceTopography's reference:
/// the channel's name, the heights in metres to 1e-12 relative (NaN at the same points,
/// their count as recorded), the grid, the sizes (1e-12) and the unit. Returns `false`
/// (with a notice) where the folder is absent.
pub(crate) fn check_shared(set: &str, name: &str, expect: Expect) -> bool {
    let Some(dir) = set_dir(set) else {
        return false;
    };
    let path = dir.join(name);
    let bytes = std::fs::read(&path).unwrap();
    let (reading, _) =
        super::detect_and_read(&path, &bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
    let json = std::fs::read_to_string(dir.join(format!("{name}.reference.json"))).unwrap();
    let meta: serde_json::Value = serde_json::from_str(&json).unwrap();
    let want: ndarray::ArrayD<f64> =
        ndarray_npy::read_npy(dir.join(format!("{name}.reference.npy"))).unwrap();
    let names: Vec<&str> = reading.channels.iter().map(|c| c.name.as_str()).collect();
    if expect.channel_names {
        let want_names: Vec<&str> = meta["channels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        assert_eq!(names, want_names, "{name}: channel names");
    }
    let c = reading
        .channels
        .iter()
        .find(|c| c.is_height)
        .expect("a height channel");
    if expect.channel_names {
        assert_eq!(c.name, meta["default_channel"].as_str().unwrap(), "{name}");
    }
    assert_heights(name, &c.heights, &want, expect.height_factor, &meta);
    let unit = match expect.unit {
        Some(u) => u.map(str::to_string),
        None => meta["unit"].as_str().map(str::to_string),
    };
    assert_eq!(c.unit, unit, "{name}: unit");
    let size = expect.size.unwrap_or_else(|| {
        let s = &meta["physical_sizes_m"];
        [s[0].as_f64(), s[1].as_f64()]
    });
    for (axis, (got, want)) in c.size.iter().zip(size).enumerate() {
        match (*got, want) {
            (Some(g), Some(w)) => assert!(
                (g - w).abs() <= 1e-12 * w.abs(),
                "{name}: size[{axis}] {g} vs {w}"
            ),
            (g, w) => assert_eq!(g, w, "{name}: size[{axis}]"),
        }
    }
    true
}

/// The heights against the reference `[x, y]` array times `factor`: grid, values to
/// 1e-12 relative, NaN at the same points and as many as recorded.
fn assert_heights(
    name: &str,
    heights: &Heights,
    want: &ndarray::ArrayD<f64>,
    factor: f64,
    meta: &serde_json::Value,
) {
    let got: Vec<f64> = match heights {
        Heights::Areal(h) => {
            assert_eq!(want.shape(), &[h.ncols(), h.nrows()], "{name}: grid [x, y]");
            h.t().iter().copied().collect()
        }
        Heights::Profile(h) => {
            assert_eq!(want.shape(), &[h.len()], "{name}: profile length");
            h.to_vec()
        }
    };
    let mut undefined = 0;
    for (i, (g, w)) in got.iter().zip(want.iter()).enumerate() {
        let w = w * factor;
        if w.is_nan() {
            undefined += 1;
            assert!(
                g.is_nan(),
                "{name} [{i}]: {g} where the reference is undefined"
            );
        } else {
            assert!(
                (g - w).abs() <= 1e-12 * w.abs(),
                "{name} [{i}]: {g} vs reference {w}"
            );
        }
    }
    assert_eq!(
        undefined as u64,
        meta["undefined_points"].as_u64().unwrap(),
        "{name}: undefined points"
    );
}
