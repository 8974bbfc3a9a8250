//! A bounded reader of NumPy `.npy` arrays (format versions 1.0, 2.0 and 3.0, as specified
//! in NumPy's `numpy/lib/format.py` and NEP 1): every real dtype converted to f64 without
//! loss, C or Fortran order.
//!
//! The file is untrusted input, so the reader
//!
//! * opens regular files only ([`crate::input::open_regular`]: a FIFO or device is refused
//!   before it can block or stream forever);
//! * reads the header in one pass over at most [`MAX_HEADER_BYTES`] bytes (the length field
//!   is checked before anything is read): a single left-to-right scan of the Python dict
//!   literal, with no recursion, so its time is linear in the header's length;
//! * accepts `descr` only as a plain type string: floats `f4`, `f8` and integers `i1`–`i8`,
//!   `u1`–`u8`, byte order `<`, `>`, `|` (one-byte types) or `=` (native); anything else
//!   (structured or nested descriptions, complex, `f2`, objects) is refused by name;
//! * checks that the shape's element count times the item size is exactly the length of
//!   the data in the file, and that the f64 array fits the memory guard
//!   ([`crate::memory::ensure_fits`]), before allocating anything sized by the header;
//! * converts losslessly: f8 and f4 exactly, integers exactly, refusing 64-bit integers of
//!   magnitude above 2^53 (the largest range in which every integer is an f64) rather than
//!   rounding them.
//!
//! Every error is one line in words and quotes at most a short, sanitised piece of the
//! header.

use std::io::Read;
use std::path::Path;

use ndarray::{ArrayD, IxDyn, ShapeBuilder};

use crate::memory::{array_bytes, ensure_fits, try_vec};
use crate::{Error, Result};

/// The largest header accepted, in bytes (NumPy's own reader refuses headers above 10 000
/// bytes by default; a float array of the maximum 64 dimensions needs under 1 500).
pub const MAX_HEADER_BYTES: usize = 10_000;

const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// The element type of a `.npy` file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    /// IEEE float of 4 or 8 bytes.
    Float(usize),
    /// Signed integer of 1, 2, 4 or 8 bytes.
    Int(usize),
    /// Unsigned integer of 1, 2, 4 or 8 bytes.
    Uint(usize),
}

impl Dtype {
    /// Bytes per element.
    pub fn size(&self) -> usize {
        match *self {
            Dtype::Float(s) | Dtype::Int(s) | Dtype::Uint(s) => s,
        }
    }
}

/// What the header of a `.npy` file says.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    /// Element type.
    pub dtype: Dtype,
    /// Whether the bytes are big-endian.
    pub big_endian: bool,
    /// Column-major data.
    pub fortran_order: bool,
    /// The array's shape (empty for a scalar).
    pub shape: Vec<usize>,
    /// Offset of the data from the start of the file.
    pub data_offset: usize,
}

impl Header {
    /// Number of elements (`None` on overflow).
    pub fn len(&self) -> Option<usize> {
        self.shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d))
    }

    /// Whether the array has no element.
    pub fn is_empty(&self) -> bool {
        self.len() == Some(0)
    }
}

/// A header error, before the path is known.
type Parse<T> = std::result::Result<T, String>;

/// Length of the fixed prefix (magic, version, header length) and of the header itself,
/// from the first bytes of the file.
fn prefix(bytes: &[u8]) -> Parse<(usize, usize, u8)> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err("not a .npy array (no \\x93NUMPY magic string at its start)".into());
    }
    let major = bytes[6];
    let (prefix, len) = match major {
        1 => (10, u16::from_le_bytes([bytes[8], bytes[9]]) as usize),
        2 | 3 if bytes.len() >= 12 => (
            12,
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
        ),
        2 | 3 => return Err("the file ends inside its .npy preamble".into()),
        v => return Err(format!("unsupported .npy format version {v} (1, 2 or 3)")),
    };
    if len > MAX_HEADER_BYTES {
        return Err(format!(
            "the .npy header claims {len} bytes, more than the {MAX_HEADER_BYTES} any plain \
             numeric array needs"
        ));
    }
    Ok((prefix, len, major))
}

/// Parses a header from the start of a file's bytes (at least the prefix and the header;
/// the data may follow). Linear in the header's length and bounded by
/// [`MAX_HEADER_BYTES`].
pub fn parse_header(bytes: &[u8]) -> Parse<Header> {
    let (start, len, major) = prefix(bytes)?;
    let Some(text) = bytes.get(start..start + len) else {
        return Err("the file ends inside its .npy header".into());
    };
    if major < 3 && !text.is_ascii() {
        return Err("the .npy header is not ASCII (versions 1 and 2 require it)".into());
    }
    let text = std::str::from_utf8(text).map_err(|_| "the .npy header is not UTF-8")?;
    let dict = parse_dict(text)?;
    let (dtype, big_endian) = parse_descr(&dict.descr)?;
    Ok(Header {
        dtype,
        big_endian,
        fortran_order: dict.fortran_order,
        shape: dict.shape,
        data_offset: start + len,
    })
}

/// The three keys of a header dict.
struct Dict {
    descr: String,
    fortran_order: bool,
    shape: Vec<usize>,
}

/// A cursor over the header text; every method advances or fails, never backtracks.
struct Scan<'a> {
    rest: &'a str,
}

impl<'a> Scan<'a> {
    fn skip_space(&mut self) {
        self.rest = self.rest.trim_start_matches([' ', '\t', '\n', '\r']);
    }

    fn eat(&mut self, c: char) -> bool {
        self.skip_space();
        match self.rest.strip_prefix(c) {
            Some(rest) => {
                self.rest = rest;
                true
            }
            None => false,
        }
    }

    fn expect(&mut self, c: char, what: &str) -> Parse<()> {
        if self.eat(c) {
            Ok(())
        } else {
            Err(format!("malformed .npy header: expected '{c}' {what}"))
        }
    }

    /// A quoted string without escapes (dict keys and type strings never need them).
    fn string(&mut self) -> Parse<&'a str> {
        self.skip_space();
        let quote = match self.rest.chars().next() {
            Some(q @ ('\'' | '"')) => q,
            _ => return Err("malformed .npy header: expected a quoted string".into()),
        };
        let body = &self.rest[1..];
        let end = body
            .find([quote, '\\'])
            .filter(|&i| body[i..].starts_with(quote))
            .ok_or("malformed .npy header: unterminated or escaped string")?;
        self.rest = &body[end + 1..];
        Ok(&body[..end])
    }

    fn word(&mut self) -> &'a str {
        self.skip_space();
        let end = self
            .rest
            .find(|c: char| !c.is_ascii_alphanumeric())
            .unwrap_or(self.rest.len());
        let (word, rest) = self.rest.split_at(end);
        self.rest = rest;
        word
    }

    /// A tuple of non-negative integers: `()`, `(3,)`, `(3, 4)`.
    fn shape(&mut self) -> Parse<Vec<usize>> {
        self.expect('(', "to open the shape")?;
        let mut shape = Vec::new();
        loop {
            if self.eat(')') {
                return Ok(shape);
            }
            let digits = self.word();
            let digits = digits.strip_suffix('L').unwrap_or(digits); // Python 2 longs
            let n = digits
                .parse::<usize>()
                .ok()
                .filter(|_| digits.bytes().all(|b| b.is_ascii_digit()))
                .ok_or("malformed .npy header: the shape holds something other than sizes")?;
            if shape.len() == 64 {
                return Err("the .npy shape has more than 64 dimensions".into());
            }
            shape.push(n);
            if !self.eat(',') {
                self.expect(')', "to close the shape")?;
                return Ok(shape);
            }
        }
    }
}

/// The header's Python dict literal: exactly the keys `descr` (a type string),
/// `fortran_order` (`True`/`False`) and `shape` (a tuple), in any order.
fn parse_dict(text: &str) -> Parse<Dict> {
    let mut scan = Scan { rest: text };
    scan.expect('{', "at the start of the header")?;
    let (mut descr, mut fortran, mut shape) = (None, None, None);
    while !scan.eat('}') {
        let key = scan.string()?;
        scan.expect(':', "after a key")?;
        match key {
            "descr" if descr.is_none() => {
                scan.skip_space();
                if !scan.rest.starts_with(['\'', '"']) {
                    return Err("the .npy descr is not a plain type string (structured or \
                                nested dtypes are not supported; save a plain numeric array)"
                        .into());
                }
                descr = Some(scan.string()?.to_string());
            }
            "fortran_order" if fortran.is_none() => {
                fortran = Some(match scan.word() {
                    "True" => true,
                    "False" => false,
                    _ => return Err("the .npy fortran_order is neither True nor False".into()),
                });
            }
            "shape" if shape.is_none() => shape = Some(scan.shape()?),
            "descr" | "fortran_order" | "shape" => {
                return Err(format!("the .npy header gives '{key}' twice"))
            }
            other => {
                return Err(format!(
                    "the .npy header has an unknown key '{}'",
                    clip(other)
                ))
            }
        }
        if !scan.eat(',') {
            scan.expect('}', "after a value")?;
            break;
        }
    }
    if !scan
        .rest
        .trim_matches([' ', '\t', '\n', '\r', '\0'])
        .is_empty()
    {
        return Err("malformed .npy header: text after the closing '}'".into());
    }
    match (descr, fortran, shape) {
        (Some(descr), Some(fortran_order), Some(shape)) => Ok(Dict {
            descr,
            fortran_order,
            shape,
        }),
        _ => Err("the .npy header lacks one of 'descr', 'fortran_order' and 'shape'".into()),
    }
}

/// At most 24 characters of untrusted text, with control characters shown as `?`.
fn clip(text: &str) -> String {
    let mut out: String = text
        .chars()
        .take(24)
        .map(|c| if c.is_control() { '?' } else { c })
        .collect();
    if text.chars().count() > 24 {
        out.push('…');
    }
    out
}

/// `<f8`, `>i4`, `|u1`, `=f4`, …: the element type and whether it is big-endian.
fn parse_descr(descr: &str) -> Parse<(Dtype, bool)> {
    let refuse = || {
        format!(
            "unsupported .npy dtype '{}' (float32/64 or 8- to 64-bit integers only)",
            clip(descr)
        )
    };
    let mut chars = descr.chars();
    let (order, kind) = (chars.next(), chars.next());
    let size: usize = chars.as_str().parse().map_err(|_| refuse())?;
    let dtype = match (kind, size) {
        (Some('f'), 4 | 8) => Dtype::Float(size),
        (Some('i'), 1 | 2 | 4 | 8) => Dtype::Int(size),
        (Some('u'), 1 | 2 | 4 | 8) => Dtype::Uint(size),
        _ => return Err(refuse()),
    };
    let big_endian = match order {
        Some('<') => false,
        Some('>') => true,
        Some('=') => cfg!(target_endian = "big"),
        Some('|') if size == 1 => false,
        _ => return Err(refuse()),
    };
    Ok((dtype, big_endian))
}

/// The largest integer magnitude below which every integer is an f64: 2^53.
const EXACT_INTEGER: u64 = 1 << 53;

/// Decodes one element to f64, exactly; `None` for a 64-bit integer beyond 2^53.
fn decode(bytes: &[u8], dtype: Dtype, big_endian: bool) -> Option<f64> {
    macro_rules! num {
        ($t:ty, $n:expr) => {{
            let raw: [u8; $n] = bytes.try_into().ok()?;
            if big_endian {
                <$t>::from_be_bytes(raw)
            } else {
                <$t>::from_le_bytes(raw)
            }
        }};
    }
    Some(match dtype {
        Dtype::Float(8) => num!(f64, 8),
        Dtype::Float(_) => num!(f32, 4) as f64,
        Dtype::Int(1) => num!(i8, 1) as f64,
        Dtype::Int(2) => num!(i16, 2) as f64,
        Dtype::Int(4) => num!(i32, 4) as f64,
        Dtype::Int(_) => {
            let v = num!(i64, 8);
            (v.unsigned_abs() <= EXACT_INTEGER).then_some(v as f64)?
        }
        Dtype::Uint(1) => num!(u8, 1) as f64,
        Dtype::Uint(2) => num!(u16, 2) as f64,
        Dtype::Uint(4) => num!(u32, 4) as f64,
        Dtype::Uint(_) => {
            let v = num!(u64, 8);
            (v <= EXACT_INTEGER).then_some(v as f64)?
        }
    })
}

fn bad(path: &Path, reason: impl Into<String>) -> Error {
    Error::BadArrayFile {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// Reads the header of the `.npy` file at `path` (a regular file), without its data.
pub fn read_header(path: &Path) -> Result<(Header, u64)> {
    let (mut file, length) = crate::input::open_regular(path)?;
    let mut head = Vec::with_capacity(64);
    let limit = (MAX_HEADER_BYTES + 12) as u64;
    (&mut file)
        .take(limit)
        .read_to_end(&mut head)
        .map_err(|e| Error::io(path, e))?;
    let header = parse_header(&head).map_err(|reason| bad(path, reason))?;
    Ok((header, length))
}

/// Reads a `.npy` file as f64 in its own shape and order (see the module docs).
pub fn read(path: &Path) -> Result<ArrayD<f64>> {
    let (mut file, length) = crate::input::open_regular(path)?;
    let mut head = Vec::with_capacity(128);
    (&mut file)
        .take((MAX_HEADER_BYTES + 12) as u64)
        .read_to_end(&mut head)
        .map_err(|e| Error::io(path, e))?;
    let header = parse_header(&head).map_err(|reason| bad(path, reason))?;
    let count = check_length(path, &header, length)?;
    ensure_fits(
        &format!(
            "reading {} (shape {})",
            path.display(),
            shape_text(&header.shape)
        ),
        array_bytes(&[count], 8),
    )?;
    let mut values = try_vec(&format!("the values of {}", path.display()), count, 0.0f64)?;
    // The bytes after the header already read, then the rest in blocks.
    let item = header.dtype.size();
    let mut pending: Vec<u8> = head.split_off(header.data_offset.min(head.len()));
    let mut block = vec![0u8; 1 << 16];
    let mut filled = 0usize;
    while filled < count {
        let whole = pending.len() / item;
        let take = whole.min(count - filled);
        for (k, chunk) in pending[..take * item].chunks_exact(item).enumerate() {
            values[filled + k] =
                decode(chunk, header.dtype, header.big_endian).ok_or_else(|| {
                    bad(
                        path,
                        format!(
                        "element {} is a 64-bit integer beyond 2^53, which float64 cannot hold \
                         exactly",
                        filled + k
                    ),
                    )
                })?;
        }
        filled += take;
        pending.drain(..take * item);
        if filled == count {
            break;
        }
        let got = file.read(&mut block).map_err(|e| Error::io(path, e))?;
        if got == 0 {
            return Err(bad(
                path,
                "the file ended before its data (it changed while read?)",
            ));
        }
        pending.extend_from_slice(&block[..got]);
    }
    let dims = IxDyn(&header.shape);
    let shape = dims.set_f(header.fortran_order);
    ArrayD::from_shape_vec(shape, values)
        .map_err(|e| bad(path, format!("inconsistent shape ({e})")))
}

/// The number of elements, checked against the length of the file: the data must be
/// exactly `count × item size` bytes after the header.
fn check_length(path: &Path, header: &Header, length: u64) -> Result<usize> {
    let shape = shape_text(&header.shape);
    let count = header.len().ok_or_else(|| {
        bad(
            path,
            format!("the shape {shape} overflows the address space"),
        )
    })?;
    let need = array_bytes(&[count], header.dtype.size());
    let have = length.saturating_sub(header.data_offset as u64);
    if need != Some(have) {
        return Err(bad(
            path,
            format!(
                "the header's shape {shape} needs {} bytes of data but the file holds {have}",
                need.map_or("more than 2^64".to_string(), |b| b.to_string())
            ),
        ));
    }
    Ok(count)
}

/// A shape as NumPy prints it: `(3, 4)`, `(5,)`, `()`.
pub fn shape_text(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A `.npy` file as NumPy's `write_array` lays it out: magic, version, little-endian
    /// header length, the dict padded with spaces to a multiple of 64 and ended by '\n'.
    fn npy(version: u8, dict: &str, data: &[u8]) -> Vec<u8> {
        let prefix = if version == 1 { 10 } else { 12 };
        let mut header = dict.to_string();
        while !(prefix + header.len() + 1).is_multiple_of(64) {
            header.push(' ');
        }
        header.push('\n');
        let mut out = MAGIC.to_vec();
        out.extend([version, 0]);
        if version == 1 {
            out.extend((header.len() as u16).to_le_bytes());
        } else {
            out.extend((header.len() as u32).to_le_bytes());
        }
        out.extend(header.as_bytes());
        out.extend(data);
        out
    }

    fn read_bytes(bytes: &[u8]) -> Result<ArrayD<f64>> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.npy");
        std::fs::write(&path, bytes).unwrap();
        read(&path)
    }

    #[test]
    fn every_supported_dtype_reads_exactly() {
        let values = [-3.0f64, 0.0, 7.0, 100.0];
        let cases: Vec<(&str, Vec<u8>)> = vec![
            ("<f8", values.iter().flat_map(|v| v.to_le_bytes()).collect()),
            (">f8", values.iter().flat_map(|v| v.to_be_bytes()).collect()),
            (
                "<f4",
                values
                    .iter()
                    .flat_map(|&v| (v as f32).to_le_bytes())
                    .collect(),
            ),
            (
                ">f4",
                values
                    .iter()
                    .flat_map(|&v| (v as f32).to_be_bytes())
                    .collect(),
            ),
            (
                "|i1",
                values
                    .iter()
                    .flat_map(|&v| (v as i8).to_le_bytes())
                    .collect(),
            ),
            (
                "<i2",
                values
                    .iter()
                    .flat_map(|&v| (v as i16).to_le_bytes())
                    .collect(),
            ),
            (
                ">i4",
                values
                    .iter()
                    .flat_map(|&v| (v as i32).to_be_bytes())
                    .collect(),
            ),
            (
                "<i8",
                values
                    .iter()
                    .flat_map(|&v| (v as i64).to_le_bytes())
                    .collect(),
            ),
            (
                "=i8",
                values
                    .iter()
                    .flat_map(|&v| (v as i64).to_ne_bytes())
                    .collect(),
            ),
        ];
        for (descr, data) in cases {
            let dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': (4,), }}");
            let a = read_bytes(&npy(1, &dict, &data)).unwrap();
            assert_eq!(a.as_slice().unwrap(), &values, "{descr}");
        }
        let unsigned = [0.0f64, 1.0, 255.0, 9.0];
        for (descr, data) in [
            (
                "|u1",
                unsigned.iter().map(|&v| v as u8).collect::<Vec<u8>>(),
            ),
            (
                "<u2",
                unsigned
                    .iter()
                    .flat_map(|&v| (v as u16).to_le_bytes())
                    .collect(),
            ),
            (
                ">u4",
                unsigned
                    .iter()
                    .flat_map(|&v| (v as u32).to_be_bytes())
                    .collect(),
            ),
            (
                "<u8",
                unsigned
                    .iter()
                    .flat_map(|&v| (v as u64).to_le_bytes())
                    .collect(),
            ),
        ] {
            let dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': (4,), }}");
            let a = read_bytes(&npy(2, &dict, &data)).unwrap();
            assert_eq!(a.as_slice().unwrap(), &unsigned, "{descr}");
        }
        // float32 → float64 is exact: 0.1f32 stays 0.1f32's value, not 0.1.
        let dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (1,), }";
        let a = read_bytes(&npy(3, dict, &0.1f32.to_le_bytes())).unwrap();
        assert_eq!(a[[0]], 0.1f32 as f64);
    }

    #[test]
    fn large_64_bit_integers_are_refused_not_rounded() {
        let dict = "{'descr': '<i8', 'fortran_order': False, 'shape': (2,), }";
        let ok: Vec<u8> = [1i64 << 53, -(1i64 << 53)]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let a = read_bytes(&npy(1, dict, &ok)).unwrap();
        assert_eq!(
            a.as_slice().unwrap(),
            &[9007199254740992.0, -9007199254740992.0]
        );
        let beyond: Vec<u8> = [0i64, (1i64 << 53) + 1]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let err = read_bytes(&npy(1, dict, &beyond)).unwrap_err().to_string();
        assert!(err.contains("element 1") && err.contains("2^53"), "{err}");
        let dict = "{'descr': '<u8', 'fortran_order': False, 'shape': (1,), }";
        let err = read_bytes(&npy(1, dict, &u64::MAX.to_le_bytes())).unwrap_err();
        assert!(err.to_string().contains("2^53"), "{err}");
    }

    #[test]
    fn fortran_order_is_honoured() {
        // The 2x3 array [[0, 1, 2], [3, 4, 5]] stored column by column.
        let data: Vec<u8> = [0.0f64, 3.0, 1.0, 4.0, 2.0, 5.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let dict = "{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3), }";
        let a = read_bytes(&npy(1, dict, &data)).unwrap();
        assert_eq!(a.shape(), &[2, 3]);
        let expected = [[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]];
        for (i, row) in expected.iter().enumerate() {
            for (j, &v) in row.iter().enumerate() {
                assert_eq!(a[[i, j]], v);
            }
        }
    }

    #[test]
    fn numpy_files_from_ndarray_npy_read_back() {
        // An independent writer (ndarray-npy, as `np.save` lays files out).
        use ndarray_npy::WriteNpyExt;
        let a = ndarray::Array2::from_shape_fn((3, 5), |(i, j)| (i * 5 + j) as f64 / 7.0);
        let mut bytes = Vec::new();
        a.write_npy(&mut bytes).unwrap();
        let b = read_bytes(&bytes).unwrap();
        assert_eq!(b, a.into_dyn());
        let t = ndarray::Array2::from_shape_fn((4, 2), |(i, j)| (i as f32) - (j as f32) * 0.5);
        let mut bytes = Vec::new();
        t.t().write_npy(&mut bytes).unwrap(); // a Fortran-order file
        let b = read_bytes(&bytes).unwrap();
        assert_eq!(b, t.t().mapv(|v| v as f64).into_dyn());
    }

    #[test]
    fn hostile_headers_are_refused_in_one_line() {
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (b"hello".to_vec(), "magic"),
            (npy(1, &format!("{{'descr': {}'<f8'{}, 'fortran_order': False, 'shape': (1,), }}", "[".repeat(24), "]".repeat(24)), &[0; 8]), "plain type string"),
            (npy(1, "{'descr': '<c16', 'fortran_order': False, 'shape': (1,), }", &[0; 16]), "dtype"),
            (npy(1, "{'descr': '<f2', 'fortran_order': False, 'shape': (1,), }", &[0; 2]), "dtype"),
            (npy(1, "{'descr': '|f8', 'fortran_order': False, 'shape': (1,), }", &[0; 8]), "dtype"),
            (npy(1, "{'descr': '<f8', 'fortran_order': False, 'shape': (4000000000, 4000000000), }", &[0; 8]), "needs"),
            (npy(1, "{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999999999999999,), }", &[0; 8]), "shape"),
            (npy(1, "{'descr': '<f8', 'fortran_order': False, 'shape': (2,), }", &[0; 8]), "needs 16 bytes"),
            (npy(1, "{'descr': '<f8', 'fortran_order': False, 'shape': (1,), 'x': 1}", &[0; 8]), "unknown key"),
            (npy(1, "{'descr': '<f8', 'fortran_order': Maybe, 'shape': (1,), }", &[0; 8]), "fortran_order"),
            (npy(1, "{'descr': '<f8', 'fortran_order': False}", &[0; 8]), "lacks"),
            (npy(1, "{'descr': '<f8\0', 'fortran_order': False, 'shape': (1,), }", &[0; 8]), "dtype"),
        ];
        for (bytes, want) in cases {
            let err = read_bytes(&bytes).unwrap_err().to_string();
            assert!(err.contains(want), "{want}: {err}");
            assert!(!err.contains('\n') && !err.contains('\0'), "{err:?}");
        }
        // A header length beyond the bound is refused from the 10-byte preamble alone.
        let mut long = MAGIC.to_vec();
        long.extend([2, 0]);
        long.extend(u32::MAX.to_le_bytes());
        assert!(parse_header(&long).unwrap_err().contains("more than"));
    }

    #[test]
    fn fifo_and_folders_are_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let err = read(dir.path()).unwrap_err().to_string();
        assert!(err.contains("not a regular file"), "{err}");
        #[cfg(unix)]
        {
            let fifo = dir.path().join("fifo.npy");
            let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
            assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
            let err = read(&fifo).unwrap_err().to_string();
            assert!(err.contains("not a regular file"), "{err}");
        }
    }

    /// Counts the inputs the property tests below try (reported by the close).
    const FUZZ_CASES: u32 = 3000;

    proptest! {
        #![proptest_config(ProptestConfig { cases: FUZZ_CASES, failure_persistence: None, ..ProptestConfig::default() })]

        /// Random bytes after a valid magic and version: never a panic, a hang or a
        /// multi-line error.
        #[test]
        fn random_headers_never_panic(version in 1u8..5, len in 0u16..400, body in proptest::collection::vec(any::<u8>(), 0..400)) {
            let mut bytes = MAGIC.to_vec();
            bytes.extend([version, 0]);
            bytes.extend(len.to_le_bytes());
            if version > 1 { bytes.extend([0, 0]); }
            bytes.extend(&body);
            if let Err(e) = parse_header(&bytes) {
                prop_assert!(!e.contains('\n') && !e.contains('\0'));
            }
        }

        /// Valid headers with mutated dicts and random data lengths: a result that is
        /// read has exactly the header's element count.
        #[test]
        fn mutated_files_are_read_or_refused(
            descr in prop::sample::select(vec!["<f8", ">f8", "<f4", "|u1", "<i2", ">u8", "<c8", "|f8", "<f2", "O", "[('a','<f8')]"]),
            fortran in any::<bool>(),
            shape in proptest::collection::vec(0usize..6, 0..4),
            extra in -9i64..9,
            cut in 0usize..200,
            flip in any::<(usize, u8)>(),
        ) {
            let dict = format!("{{'descr': '{descr}', 'fortran_order': {}, 'shape': ({}), }}",
                if fortran { "True" } else { "False" },
                shape.iter().map(|d| format!("{d},")).collect::<String>());
            let item = descr.get(2..).and_then(|s| s.parse::<usize>().ok()).unwrap_or(8);
            let n: usize = shape.iter().product();
            let data = vec![1u8; ((n * item) as i64 + extra).max(0) as usize];
            let mut bytes = npy(1, &dict, &data);
            if cut % 3 == 0 && !bytes.is_empty() {
                let i = flip.0 % bytes.len();
                bytes[i] ^= flip.1;
            } else if cut % 3 == 1 {
                bytes.truncate(bytes.len().saturating_sub(cut));
            }
            match read_bytes(&bytes) {
                Ok(a) => prop_assert_eq!(a.len(), a.shape().iter().product::<usize>()),
                Err(e) => {
                    let e = e.to_string();
                    prop_assert!(!e.contains('\n') && !e.contains('\0'), "{}", e);
                }
            }
        }
    }

    #[test]
    fn deep_nesting_is_refused_in_linear_time() {
        // 100 000 nested brackets: rejected at once (the old parser doubled per level).
        let mut bytes = MAGIC.to_vec();
        bytes.extend([1, 0]);
        let dict = format!("{{'descr': {}", "[".repeat(9_000));
        bytes.extend((dict.len() as u16).to_le_bytes());
        bytes.extend(dict.as_bytes());
        let start = std::time::Instant::now();
        assert!(parse_header(&bytes).is_err());
        // Microseconds when linear, forever when exponential; room for a busy machine.
        assert!(start.elapsed() < std::time::Duration::from_secs(20));
    }
}
