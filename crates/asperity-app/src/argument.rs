//! Any surface or line argument, in every command and in Python's `read_topography`,
//! becomes a [`Topography`] through one call ([`open`]).
//!
//! * A measured file (any format the library reads), or an `.npy` written by `asperity
//!   import` (its sidecar gives `sizes` per axis), goes through the measured reader
//!   ([`crate::measured::open`]: channel, sizes, levelling, filling, warnings).
//! * A plain `.npy` (a generated surface or line, a user's array) is read as it is where the
//!   caller asks for [`Arrays::Plain`]: its memory checked from its header before its data
//!   are read, its side length from the request, else its sidecar's `spec.size`, else 1,
//!   its pixels square unless the request gives both sizes. Otherwise ([`Arrays::Measured`])
//!   it goes through the measured reader too, which needs a size from the request or the
//!   sidecar.
//!
//! A sidecar beside an `.npy` is read by one set of rules whatever the command
//! ([`asperity::input::read_sidecar`]): a regular file (a FIFO is refused, not waited on),
//! bounded in size, valid JSON with a positive `spec.size` where it has one; a missing
//! sidecar is not an error.
//!
//! ```
//! use asperity_app::argument::{open, Arrays, Dims, SizeSource};
//! use asperity_app::measured::MeasuredRequest;
//!
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("s.npy");
//! let heights = ndarray::Array2::from_shape_fn((4, 8), |(i, j)| (i * j) as f64);
//! asperity::io::write_npy_2d(&path, false, &heights).unwrap();
//! let no_check = |_: &[usize]| Ok(());
//! let input = open(&path, &MeasuredRequest::default(), Arrays::Plain(Dims::Map, &no_check), None)
//!     .unwrap();
//! assert_eq!(input.size_source, SizeSource::Default);
//! assert_eq!(input.topography.sizes, vec![1.0, 0.5]); // square pixels
//! assert!(!input.measured);
//! ```

use std::path::Path;

use asperity::topography::{Fill, Heights, Provenance, Topography};

use crate::measured::{MeasuredRequest, Warning};
use crate::refusal::{positive, Refusal, RequestError};
use crate::surface::params::SIZE;

/// The dimensions a command reads a plain array as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dims {
    /// A 2D surface (rows along y) of at least 2×2 points.
    Map,
    /// A 1D line of at least 2 points.
    Line,
    /// Either.
    Either,
}

/// The check of a plain array's shape (from its header) before its data are read.
pub type ShapeCheck<'a> = &'a dyn Fn(&[usize]) -> asperity::Result<()>;

/// How a plain `.npy` (one with no import sidecar) is read.
#[derive(Clone, Copy)]
pub enum Arrays<'a> {
    /// As a measured file (`asperity import`, `contact`, Python's `read_topography`).
    Measured,
    /// As it is, of these dimensions; the shape is handed to the check (memory) before the
    /// data are read.
    Plain(Dims, ShapeCheck<'a>),
}

/// Where the side length came from, as a run's record names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SizeSource {
    /// The request (`--size`, `size=`).
    Flag,
    /// A plain array's sidecar (`spec.size`).
    Sidecar,
    /// The measured file (or an imported array's sidecar).
    File,
    /// Neither: [`crate::surface::DEFAULT_SIZE`].
    Default,
}

impl SizeSource {
    /// The name in records: `--size`, `sidecar`, `file`, `default`.
    pub fn name(self) -> &'static str {
        match self {
            SizeSource::Flag => "--size",
            SizeSource::Sidecar => "sidecar",
            SizeSource::File => "file",
            SizeSource::Default => "default",
        }
    }
}

/// A surface or line argument, opened.
#[derive(Debug, Clone)]
pub struct Input {
    /// The heights, sizes and provenance.
    pub topography: Topography,
    /// What the user should know (measured files only).
    pub warnings: Vec<Warning>,
    /// Where the side length came from.
    pub size_source: SizeSource,
    /// Whether it went through the measured reader (its provenance is its record).
    pub measured: bool,
    /// A plain array's sidecar (a generator's spec), where it has one.
    pub sidecar: Option<serde_json::Value>,
}

/// Whether `path` is a NumPy `.npy` file (by its magic bytes; only a regular file is
/// opened, so a FIFO is not waited on: it is not an array, and the reader it goes to
/// refuses it in one line).
pub fn is_npy(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 6];
    asperity::input::open_regular(path).is_ok_and(|(mut f, _)| f.read_exact(&mut head).is_ok())
        && &head == b"\x93NUMPY"
}

/// The sidecar of a file a front end saved and loads back (Python's `asperity.load`: a
/// surface's `.npy`, a sweep's `.npz`, …), by the rules of every input: the file itself
/// must be a regular file (a FIFO is refused, not waited on), and its sidecar, where it
/// has one, is read by [`asperity::input::read_sidecar`] (regular, bounded, valid JSON).
/// `Ok(None)`: no sidecar.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("s.npz");
/// std::fs::write(&path, b"PK").unwrap();
/// std::fs::write(dir.path().join("s.npz.json"), b"{\"kind\": \"sweep\"").unwrap();
/// let refusal = asperity_app::argument::saved_sidecar(&path).unwrap_err().to_string();
/// assert!(refusal.contains("is a corrupt sidecar (not JSON"), "{refusal}");
/// ```
pub fn saved_sidecar(path: &Path) -> asperity::Result<Option<serde_json::Value>> {
    asperity::input::open_regular(path)?;
    asperity::input::read_sidecar(path)
}

/// The side lengths a request gives a surface or line argument (`--size X[,Y]`, Python's
/// `size=x` or `size=(x, y)`): one (x; y from square pixels) or two, each positive and
/// finite, by one rule in one wording for both front ends (the CLI parses the text first).
///
/// ```
/// use asperity_app::argument::sizes;
/// use asperity_app::Names;
///
/// assert_eq!(sizes(&[2e-6]).unwrap(), [Some(2e-6), None]);
/// assert_eq!(sizes(&[2e-6, 1e-6]).unwrap(), [Some(2e-6), Some(1e-6)]);
/// let refused = |v: &[f64]| sizes(v).unwrap_err().words(Names::Flags);
/// assert_eq!(refused(&[1.0, -1.0]), "--size must be positive and finite, got -1");
/// assert_eq!(refused(&[1.0, 2.0, 3.0]), "--size takes one value (x) or two (x and y), got 3");
/// ```
pub fn sizes(values: &[f64]) -> Result<[Option<f64>; 2], Refusal> {
    if values.is_empty() || values.len() > 2 {
        return Err(Refusal::of(SIZE).text(format!(
            " takes one value (x) or two (x and y), got {}",
            values.len()
        )));
    }
    let mut out = [None, None];
    for (slot, &value) in out.iter_mut().zip(values) {
        *slot = Some(positive(SIZE, value)?);
    }
    Ok(out)
}

fn library(e: asperity::Error) -> RequestError {
    RequestError::Invalid(Box::new(e))
}

/// Opens `path` as `request` says (see the module docs); undefined points of a measured
/// file with no filling named get `unfilled` (see [`crate::measured::open`]).
pub fn open(
    path: &Path,
    request: &MeasuredRequest,
    arrays: Arrays<'_>,
    unfilled: Option<Fill>,
) -> Result<Input, RequestError> {
    let sidecar = is_npy(path).then(|| asperity::input::read_sidecar(path));
    let imported = matches!(&sidecar, Some(Ok(Some(v))) if v["sizes"].is_array());
    match arrays {
        Arrays::Plain(dims, fits) if sidecar.is_some() && !imported => {
            let sidecar = sidecar.expect("an .npy");
            plain(path, request.size, (dims, fits), sidecar)
        }
        _ => {
            // A sidecar that cannot be read is refused before the measured reader.
            sidecar.transpose().map_err(library)?;
            let opened = crate::measured::open(path, request, unfilled)?;
            Ok(Input {
                topography: opened.topography,
                warnings: opened.warnings,
                size_source: match request.size {
                    Some(_) => SizeSource::Flag,
                    None => SizeSource::File,
                },
                measured: true,
                sidecar: None,
            })
        }
    }
}

/// A plain array: the shape checked, the sidecar's refusal (if any), the data, the sizes.
fn plain(
    path: &Path,
    size: Option<[Option<f64>; 2]>,
    (dims, fits): (Dims, ShapeCheck<'_>),
    sidecar: asperity::Result<Option<serde_json::Value>>,
) -> Result<Input, RequestError> {
    fits(&asperity::io::read_npy_shape(path).map_err(library)?).map_err(library)?;
    let sidecar = sidecar.map_err(library)?;
    let heights = read_heights(path, dims)?;
    let [size_x, size_y] = size.unwrap_or([None, None]);
    let sidecar_size = sidecar.as_ref().and_then(|v| v["spec"]["size"].as_f64());
    let (x, size_source) = match (size_x, sidecar_size) {
        (Some(x), _) => (x, SizeSource::Flag),
        (None, Some(x)) => (x, SizeSource::Sidecar),
        (None, None) => (crate::surface::DEFAULT_SIZE, SizeSource::Default),
    };
    let sizes = match &heights {
        Heights::Profile(_) => vec![x],
        Heights::Areal(h) => vec![x, size_y.unwrap_or(x * h.nrows() as f64 / h.ncols() as f64)],
    };
    let provenance = Provenance {
        source: path.to_path_buf(),
        format: "npy".into(),
        channel: "heights".into(),
        channel_index: 0,
        channels: vec!["heights".into()],
        file_unit: None,
        unit: None,
        size_source: size_source.name().into(),
        cleaning: Vec::new(),
    };
    Ok(Input {
        topography: Topography {
            heights,
            sizes,
            provenance,
        },
        warnings: Vec::new(),
        size_source,
        measured: false,
        sidecar,
    })
}

/// The heights of a plain array of `dims` (finite, not empty, at least 2 points a side).
fn read_heights(path: &Path, dims: Dims) -> Result<Heights, RequestError> {
    Ok(match dims {
        Dims::Map => Heights::Areal(asperity::io::read_npy_2d(path).map_err(library)?),
        Dims::Line => Heights::Profile(asperity::io::read_npy_1d(path).map_err(library)?),
        Dims::Either => {
            let array = asperity::io::read_npy(path).map_err(library)?;
            Heights::from_array(array).map_err(|d| {
                Refusal::saying(format!(
                    "{}: expected a 1D line or 2D surface, found {d} dimensions",
                    path.display()
                ))
            })?
        }
    })
}

#[cfg(test)]
mod tests {
    use std::cell::RefCell;

    use super::*;
    use crate::refusal::Names;

    fn array(dir: &Path, name: &str, shape: (usize, usize)) -> std::path::PathBuf {
        let path = dir.join(name);
        let heights = ndarray::Array2::from_shape_fn(shape, |(i, j)| (i + 2 * j) as f64);
        asperity::io::write_npy_2d(&path, false, &heights).unwrap();
        path
    }

    fn sidecar(path: &Path, text: &str) {
        std::fs::write(asperity::io::sidecar_path(path), text).unwrap();
    }

    fn map(fits: ShapeCheck<'_>) -> Arrays<'_> {
        Arrays::Plain(Dims::Map, fits)
    }

    fn with_size(x: f64) -> MeasuredRequest {
        MeasuredRequest {
            size: Some([Some(x), None]),
            ..MeasuredRequest::default()
        }
    }

    #[test]
    fn a_plain_array_takes_its_size_from_the_request_then_its_sidecar_then_one() {
        let dir = tempfile::tempdir().unwrap();
        let path = array(dir.path(), "s.npy", (4, 8));
        let shapes = RefCell::new(Vec::new());
        let fits = |shape: &[usize]| {
            shapes.borrow_mut().push(shape.to_vec());
            Ok(())
        };
        let none = MeasuredRequest::default();
        let input = open(&path, &none, map(&fits), None).unwrap();
        assert_eq!(
            (input.size_source, input.topography.sizes),
            (SizeSource::Default, vec![1.0, 0.5])
        );
        sidecar(
            &path,
            r#"{"kind": "surface", "spec": {"size": 2.0, "psd": {}}}"#,
        );
        let input = open(&path, &none, map(&fits), None).unwrap();
        assert_eq!(
            (input.size_source, input.topography.sizes),
            (SizeSource::Sidecar, vec![2.0, 1.0])
        );
        assert_eq!(input.sidecar.unwrap()["kind"], "surface");
        let both = MeasuredRequest {
            size: Some([Some(3.0), Some(5.0)]),
            ..MeasuredRequest::default()
        };
        let input = open(&path, &both, map(&fits), None).unwrap();
        assert_eq!(
            (input.size_source, input.topography.sizes),
            (SizeSource::Flag, vec![3.0, 5.0])
        );
        assert!(!input.measured);
        assert_eq!(shapes.into_inner(), vec![vec![4, 8]; 3]);
    }

    #[test]
    fn the_memory_check_refuses_before_the_data_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = array(dir.path(), "s.npy", (4, 8));
        // A corrupt sidecar would be refused later: the check comes first.
        sidecar(&path, "{not json");
        let refuse = |shape: &[usize]| {
            Err(asperity::Error::invalid(
                "grid",
                format!("{shape:?} too large"),
            ))
        };
        let err = open(&path, &MeasuredRequest::default(), map(&refuse), None).unwrap_err();
        assert!(
            err.words(Names::Flags).contains("[4, 8] too large"),
            "{err}"
        );
    }

    #[test]
    fn a_corrupt_or_fifo_sidecar_is_refused_whatever_the_size_and_mode() {
        let dir = tempfile::tempdir().unwrap();
        let path = array(dir.path(), "s.npy", (4, 8));
        sidecar(&path, "{not json");
        let ok = |_: &[usize]| Ok(());
        for arrays in [map(&ok), Arrays::Measured] {
            let err = open(&path, &with_size(2.0), arrays, None).unwrap_err();
            assert!(err.words(Names::Flags).contains("corrupt sidecar"), "{err}");
        }
        #[cfg(unix)]
        {
            let fifo = array(dir.path(), "f.npy", (4, 8));
            let made = std::process::Command::new("mkfifo")
                .arg(asperity::io::sidecar_path(&fifo))
                .status()
                .unwrap();
            assert!(made.success());
            for arrays in [map(&ok), Arrays::Measured] {
                let err = open(&fifo, &with_size(2.0), arrays, None).unwrap_err();
                assert!(
                    err.words(Names::Flags).contains("not a regular file"),
                    "{err}"
                );
            }
        }
    }

    #[test]
    fn an_imported_array_and_a_measured_file_go_through_the_measured_reader() {
        let dir = tempfile::tempdir().unwrap();
        let path = array(dir.path(), "t.npy", (4, 8));
        sidecar(
            &path,
            r#"{"kind": "measured surface", "sizes": [4e-6, 2e-6], "unit": "m", "cleaning": ["plane"]}"#,
        );
        let never = |_: &[usize]| -> asperity::Result<()> { panic!("not a plain array") };
        let input = open(&path, &MeasuredRequest::default(), map(&never), None).unwrap();
        assert!(input.measured);
        assert_eq!(input.size_source, SizeSource::File);
        assert_eq!(input.topography.sizes, vec![4e-6, 2e-6]);
        assert_eq!(
            input.topography.provenance.cleaning,
            vec!["plane".to_string()]
        );
        let text = dir.path().join("m.txt");
        std::fs::write(&text, "# Value units: m\n1 2 3\n4 5 6\n7 8 9\n").unwrap();
        let input = open(&text, &with_size(1e-6), map(&never), None).unwrap();
        assert!(input.measured && input.size_source == SizeSource::Flag);
    }

    #[test]
    fn a_plain_array_of_the_wrong_dimensions_is_refused_in_one_line() {
        let dir = tempfile::tempdir().unwrap();
        let ok = |_: &[usize]| Ok(());
        let cube = dir.path().join("c.npy");
        // A 2×2×2 float64 array, header by hand (NPY 1.0, padded to 64 bytes).
        let mut header =
            "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2, 2), }".to_string();
        while !(10 + header.len() + 1).is_multiple_of(64) {
            header.push(' ');
        }
        header.push('\n');
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend((header.len() as u16).to_le_bytes());
        bytes.extend(header.bytes());
        bytes.extend([0u8; 64]);
        std::fs::write(&cube, bytes).unwrap();
        let err = open(
            &cube,
            &MeasuredRequest::default(),
            Arrays::Plain(Dims::Either, &ok),
            None,
        )
        .unwrap_err();
        assert!(
            err.words(Names::Flags)
                .ends_with("c.npy: expected a 1D line or 2D surface, found 3 dimensions"),
            "{err}"
        );
        let map2 = array(dir.path(), "s.npy", (4, 8));
        let err = open(
            &map2,
            &MeasuredRequest::default(),
            Arrays::Plain(Dims::Line, &ok),
            None,
        )
        .unwrap_err();
        assert!(
            err.words(Names::Flags).contains("expected a 1D (n,) array"),
            "{err}"
        );
        let line = open(
            &map2,
            &MeasuredRequest::default(),
            Arrays::Plain(Dims::Either, &ok),
            None,
        )
        .unwrap();
        assert!(matches!(line.topography.heights, Heights::Areal(_)));
    }
}
