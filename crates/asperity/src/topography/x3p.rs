//! ISO 25178-72 / ISO 5436-2 XML 3D surface profiles (X3P): reader and writer.
//!
//! An X3P file is a zip archive holding `main.xml` and a binary payload. `main.xml`
//! (root `ISO5436_2`) gives in `Record1` the feature type (`SUR`: a map, `PRF`: a
//! profile) and the axes: `CX`, `CY` incremental (`AxisType` `I`) with their spacing
//! `Increment` in metres, `CZ` absolute (`A`) with its `DataType` (`I`: int16, `L`: int32,
//! `F`: float32, `D`: float64) and, for integers, `Increment` and `Offset`
//! (`z = Offset + Increment · raw`); in `Record3` the grid (`MatrixDimension`: `SizeX`,
//! `SizeY`, `SizeZ` = 1) and the data: a `PointDataLink` to the payload (little-endian,
//! x fastest, then y — our row-major order with rows along y), or inline `DataList`
//! `Datum` elements; an optional `ValidPointsLink` names a bit array (least significant
//! bit first, 1 = valid). Float NaN and empty `Datum`s are undefined points. `CX` and
//! `CY` may also be absolute (`A`, with their own `DataType`, `Increment`, `Offset`): each
//! point's record then holds its coordinates before its height (binary: x, y, z values
//! back to back; inline: `x;y;z`), and the coordinates must form a uniform grid (x by
//! column, y by row, increasing, within a thousandth of a step), whose step is the
//! spacing; other point sets are refused (openGPS's description of ISO 5436-2; Gwyddion
//! and SurfaceTopography refuse absolute lateral axes). Sizes are
//! `Increment × count` per axis (SurfaceTopography's convention; its arrays are our
//! transpose). Facts from the openGPS description of ISO 5436-2 and SurfaceTopography's
//! `X3PReader`; where they differ, the standard is followed: `I`/`L` are signed.
//!
//! Untrusted archives: `main.xml` is read up to 16 MiB; a payload is read only when its
//! size follows from the grid, at most 1100 × its compressed size (deflate cannot do
//! better) and within the memory available. The payload is streamed (256 KiB at a time, a
//! second thread running its MD5 and decoding beside the inflate) straight into the
//! heights, sized once from the header; `read_file` reads an X3P archive from the file
//! itself (`read_from_file`), never holding it whole.

use std::io::{Cursor, Read, Seek, Write};
use std::path::Path;

use md5::{Digest, Md5};
use ndarray::{Array1, Array2, ArrayView2};
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipArchive, ZipWriter};

use super::{bad, Channel, Heights, Reading};
use crate::{Error, Result};

const FORMAT: &str = "x3p";
const ZIP_MAGIC: &[u8] = b"PK\x03\x04";
const MAX_XML: u64 = 16 << 20;
/// The largest ratio of uncompressed to compressed size deflate can reach is about 1032.
const MAX_RATIO: u64 = 1100;

/// A zip archive that holds a `main.xml`.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.starts_with(ZIP_MAGIC)
        && ZipArchive::new(Cursor::new(bytes))
            .map(|mut z| z.by_name("main.xml").is_ok())
            .unwrap_or(false)
}

fn zip_error(e: zip::result::ZipError) -> Error {
    bad(FORMAT, format!("not a readable zip archive ({e})"))
}

/// One child element by local name.
fn child<'a, 'i>(node: roxmltree::Node<'a, 'i>, name: &str) -> Option<roxmltree::Node<'a, 'i>> {
    node.children().find(|c| c.tag_name().name() == name)
}

/// The text of the element at `path` under `node`.
fn text_at<'a>(node: roxmltree::Node<'a, '_>, path: &[&str]) -> Option<&'a str> {
    let mut n = node;
    for name in path {
        n = child(n, name)?;
    }
    n.text().map(str::trim)
}

fn required<'a>(node: roxmltree::Node<'a, '_>, path: &[&str]) -> Result<&'a str> {
    text_at(node, path).ok_or_else(|| bad(FORMAT, format!("main.xml has no {}", path.join("/"))))
}

fn number<T: std::str::FromStr>(node: roxmltree::Node<'_, '_>, path: &[&str]) -> Result<T> {
    let text = required(node, path)?;
    text.parse().map_err(|_| {
        bad(
            FORMAT,
            format!("{} = {text:?} is not a valid number", path.join("/")),
        )
    })
}

/// What `main.xml` says about the data.
struct Layout {
    profile: bool,
    nx: usize,
    ny: usize,
    spacing: [f64; 2],
    /// The coding of CX and CY where they are absolute (coordinates stored per point).
    absolute: [Option<Coding>; 2],
    data_type: char,
    z_increment: f64,
    z_offset: f64,
    payload: Option<String>,
    payload_md5: Option<String>,
    valid_points: Option<String>,
    valid_md5: Option<String>,
}

/// How an axis' values are stored: `DataType` (`I`, `L`, `F`, `D`), and `value = Offset +
/// Increment · raw` (defaults 0 and 1).
#[derive(Debug, Clone, Copy)]
struct Coding {
    data_type: char,
    increment: f64,
    offset: f64,
}

impl Coding {
    fn width(&self) -> usize {
        match self.data_type {
            'I' => 2,
            'L' | 'F' => 4,
            _ => 8,
        }
    }

    fn raw(&self, b: &[u8]) -> f64 {
        match self.data_type {
            'I' => i16::from_le_bytes([b[0], b[1]]) as f64,
            'L' => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            'F' => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            _ => f64::from_le_bytes(b[..8].try_into().expect("8 bytes")),
        }
    }

    fn value(&self, raw: f64) -> f64 {
        self.offset + self.increment * raw
    }
}

fn coding(record1: roxmltree::Node<'_, '_>, axis: &str) -> Result<Coding> {
    let data_type = match required(record1, &["Axes", axis, "DataType"])? {
        t @ ("I" | "L" | "F" | "D") => t.chars().next().expect("one letter"),
        other => {
            return Err(bad(
                FORMAT,
                format!("{axis} DataType {other} is not one of I, L, F, D"),
            ))
        }
    };
    let optional = |name: &str, default: f64| -> Result<f64> {
        match text_at(record1, &["Axes", axis, name]) {
            None | Some("") => Ok(default),
            Some(_) => number(record1, &["Axes", axis, name]),
        }
    };
    let c = Coding {
        data_type,
        increment: optional("Increment", 1.0)?,
        offset: optional("Offset", 0.0)?,
    };
    if !(c.increment.is_finite() && c.increment != 0.0 && c.offset.is_finite()) {
        return Err(bad(
            FORMAT,
            format!("{axis} Increment or Offset is not finite and non-zero"),
        ));
    }
    Ok(c)
}

fn layout(root: roxmltree::Node<'_, '_>) -> Result<Layout> {
    let record1 = child(root, "Record1").ok_or_else(|| bad(FORMAT, "main.xml has no Record1"))?;
    let record3 = child(root, "Record3").ok_or_else(|| bad(FORMAT, "main.xml has no Record3"))?;
    let profile = match required(record1, &["FeatureType"])? {
        "SUR" => false,
        "PRF" => true,
        other => {
            return Err(bad(
                FORMAT,
                format!("FeatureType {other} is not supported (SUR, PRF)"),
            ))
        }
    };
    let mut absolute = [None, None];
    for (k, axis) in ["CX", "CY"].into_iter().enumerate() {
        match required(record1, &["Axes", axis, "AxisType"])? {
            "I" => {}
            "A" => absolute[k] = Some(coding(record1, axis)?),
            kind => {
                return Err(bad(
                    FORMAT,
                    format!("{axis} AxisType {kind}: neither incremental (I) nor absolute (A)"),
                ))
            }
        }
    }
    let z = coding(record1, "CZ")?;
    if child(record3, "MatrixDimension").is_none() {
        return Err(bad(
            FORMAT,
            "only MatrixDimension grids are supported (no ListDimension)",
        ));
    }
    let nz: usize = number(record3, &["MatrixDimension", "SizeZ"])?;
    if nz != 1 {
        return Err(bad(
            FORMAT,
            format!("SizeZ = {nz}: volumetric data is not supported"),
        ));
    }
    // An absolute axis' spacing follows from its coordinates (see `absolute_spacing`).
    let spacing = |k: usize, axis: &str| match absolute[k] {
        Some(_) => Ok(1.0),
        None if k == 1 && profile => Ok(1.0),
        None => number(record1, &["Axes", axis, "Increment"]),
    };
    Ok(Layout {
        profile,
        nx: number(record3, &["MatrixDimension", "SizeX"])?,
        ny: number(record3, &["MatrixDimension", "SizeY"])?,
        spacing: [spacing(0, "CX")?, spacing(1, "CY")?],
        absolute,
        data_type: z.data_type,
        z_increment: z.increment,
        z_offset: z.offset,
        payload: text_at(record3, &["DataLink", "PointDataLink"]).map(str::to_string),
        payload_md5: text_at(record3, &["DataLink", "MD5ChecksumPointData"]).map(str::to_string),
        // The valid-points link sits in `DataLink` (openGPS samples) or in `Record3`.
        valid_points: text_at(record3, &["DataLink", "ValidPointsLink"])
            .or_else(|| text_at(record3, &["ValidPointsLink"]))
            .filter(|s| !s.is_empty())
            .map(str::to_string),
        valid_md5: text_at(record3, &["DataLink", "MD5ChecksumValidPoints"])
            .or_else(|| text_at(record3, &["MD5ChecksumValidPoints"]))
            .map(str::to_string),
    })
}

impl Layout {
    fn validate(&self) -> Result<usize> {
        if self.nx < 2 || (!self.profile && self.ny < 2) || (self.profile && self.ny != 1) {
            return Err(bad(
                FORMAT,
                format!(
                    "a {} of {} x {} points",
                    if self.profile { "profile" } else { "map" },
                    self.nx,
                    self.ny
                ),
            ));
        }
        for v in self.spacing.iter().chain([&self.z_increment]) {
            if !(v.is_finite() && *v > 0.0) {
                return Err(bad(
                    FORMAT,
                    format!("increment {v} is not positive and finite"),
                ));
            }
        }
        if !self.z_offset.is_finite() {
            return Err(bad(FORMAT, "CZ Offset is not finite"));
        }
        self.nx
            .checked_mul(self.ny)
            .filter(|&n| n <= isize::MAX as usize / 8)
            .ok_or_else(|| bad(FORMAT, "the grid is larger than any memory"))
    }

    fn z_coding(&self) -> Coding {
        Coding {
            data_type: self.data_type,
            increment: self.z_increment,
            offset: self.z_offset,
        }
    }

    /// The bytes of one point's record: the absolute axes' values in order x, y, then z.
    fn record_width(&self) -> usize {
        self.absolute
            .iter()
            .flatten()
            .map(Coding::width)
            .sum::<usize>()
            + self.z_coding().width()
    }

    /// Decodes one record (of [`Self::record_width`] bytes) into `out`.
    fn push_record(&self, mut record: &[u8], out: &mut Records) {
        for (k, c) in self.absolute.iter().enumerate() {
            if let Some(c) = c {
                let v = c.value(c.raw(record));
                record = &record[c.width()..];
                if k == 0 {
                    out.x.push(v)
                } else {
                    out.y.push(v)
                }
            }
        }
        out.z.push(self.scale(self.z_coding().raw(record)));
    }

    /// Decodes the whole records of `piece` into `out` (see [`Self::push_record`]); heights
    /// alone (no absolute axis) go straight into `out.z`, one loop per data type.
    fn decode(&self, piece: &[u8], out: &mut Records) {
        if self.absolute.iter().any(Option::is_some) {
            for record in piece.chunks_exact(self.record_width()) {
                self.push_record(record, out);
            }
            return;
        }
        let scale = self.scaler();
        let z = &mut out.z;
        match self.data_type {
            'I' => z.extend(
                piece
                    .chunks_exact(2)
                    .map(|b| scale(i16::from_le_bytes([b[0], b[1]]) as f64)),
            ),
            'L' => z.extend(
                piece
                    .chunks_exact(4)
                    .map(|b| scale(i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64)),
            ),
            'F' => z.extend(
                piece
                    .chunks_exact(4)
                    .map(|b| scale(f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64)),
            ),
            _ => z.extend(
                piece
                    .chunks_exact(8)
                    .map(|b| scale(f64::from_le_bytes(b.try_into().expect("8 bytes")))),
            ),
        }
    }

    fn scale(&self, v: f64) -> f64 {
        self.scaler()(v)
    }

    /// A height from its stored value: `Offset + Increment · raw` for integers or where an
    /// increment or offset is given, the value itself otherwise; non-finite: undefined.
    fn scaler(&self) -> impl Fn(f64) -> f64 {
        let affine = self.data_type == 'I'
            || self.data_type == 'L'
            || self.z_increment != 1.0
            || self.z_offset != 0.0;
        let (increment, offset) = (self.z_increment, self.z_offset);
        move |v| {
            let z = if affine { offset + increment * v } else { v };
            if z.is_finite() {
                z
            } else {
                f64::NAN
            }
        }
    }
}

/// Opens the archive entry `name`, which must declare exactly `len` bytes (a payload that
/// does not match the grid and data type of `main.xml` is refused) and be able to come
/// from its compressed size ([`MAX_RATIO`]); nothing is allocated.
fn open_entry<'a, R: Read + Seek>(
    archive: &'a mut ZipArchive<R>,
    name: &str,
    len: usize,
) -> Result<zip::read::ZipFile<'a, R>> {
    let file = archive
        .by_name(name)
        .map_err(|_| bad(FORMAT, format!("the archive has no {name}")))?;
    let declared = file.size();
    if declared != len as u64 {
        return Err(bad(
            FORMAT,
            format!(
                "{name} holds {declared} bytes where the grid and data type of main.xml need {len}"
            ),
        ));
    }
    if (len as u64)
        > file
            .compressed_size()
            .saturating_mul(MAX_RATIO)
            .max(1 << 20)
    {
        return Err(bad(
            FORMAT,
            format!(
                "{name}: {len} bytes cannot come from {} compressed bytes",
                file.compressed_size()
            ),
        ));
    }
    Ok(file)
}

/// Reads an archive entry of exactly `len` bytes whole (see [`open_entry`]), checked
/// against the memory before allocating, and read to its end so that the zip CRC-32 is
/// verified. For small entries (the valid-points bits); the payload is streamed.
fn entry<R: Read + Seek>(archive: &mut ZipArchive<R>, name: &str, len: usize) -> Result<Vec<u8>> {
    crate::memory::ensure_fits(&format!("reading {name} of an X3P file"), Some(len as u64))?;
    let mut data = Vec::with_capacity(len);
    let file = open_entry(archive, name, len)?;
    file.take(len as u64 + 1)
        .read_to_end(&mut data)
        .map_err(|e| entry_error(name, e))?;
    if data.len() != len {
        return Err(bad(
            FORMAT,
            format!("{name} holds {} bytes, not the {len} declared", data.len()),
        ));
    }
    Ok(data)
}

/// The most bytes of an entry held at a time in one buffer while it is streamed.
const PIECE: usize = 1 << 18;
/// The buffers in flight between the thread that inflates an entry and the one that
/// checks and decodes it: a fixed pool, so at most `IN_FLIGHT × PIECE` bytes are held.
const IN_FLIGHT: usize = 4;

/// Streams the archive entry `name` of exactly `len` bytes (see [`open_entry`]) to `sink`
/// in pieces of whole `unit`s (at most [`PIECE`] bytes), each also given to `md5` where
/// there is one; read to its end so that the zip CRC-32 is verified. `len` must be a
/// multiple of `unit`. An entry of more than one piece is inflated on this thread while a
/// second one runs the MD5 and `sink` on the pieces already read (in order, through a
/// pool of [`IN_FLIGHT`] buffers: nothing else is buffered); a smaller one reads on this
/// thread alone.
fn stream_entry<R: Read + Seek>(
    archive: &mut ZipArchive<R>,
    name: &str,
    len: usize,
    unit: usize,
    mut md5: Option<&mut Md5>,
    mut sink: impl FnMut(&[u8]) + Send,
) -> Result<()> {
    let piece = unit * (PIECE / unit).max(1);
    let reader = open_entry(archive, name, len)?.take(len as u64 + 1);
    let mut use_piece = move |buf: &[u8]| {
        if let Some(md5) = md5.as_deref_mut() {
            md5.update(buf);
        }
        sink(buf);
    };
    if len < piece {
        let spare = std::cell::Cell::new(Some(vec![0u8; piece]));
        return pump(
            reader,
            name,
            len,
            unit,
            piece,
            || spare.take(),
            |buf, filled| {
                use_piece(&buf[..filled]);
                spare.set(Some(buf));
                true
            },
        );
    }
    std::thread::scope(|scope| {
        let (full_tx, full_rx) = std::sync::mpsc::sync_channel::<(Vec<u8>, usize)>(IN_FLIGHT);
        let (empty_tx, empty_rx) = std::sync::mpsc::sync_channel::<Vec<u8>>(IN_FLIGHT);
        for _ in 0..IN_FLIGHT {
            empty_tx
                .send(vec![0u8; piece])
                .expect("the pool's channel is open");
        }
        let worker = scope.spawn(move || {
            for (buf, filled) in full_rx {
                use_piece(&buf[..filled]);
                // The reading thread may have stopped on an error: nothing to give back to.
                let _ = empty_tx.send(buf);
            }
        });
        let read = pump(
            reader,
            name,
            len,
            unit,
            piece,
            || empty_rx.recv().ok(),
            |buf, filled| full_tx.send((buf, filled)).is_ok(),
        );
        drop(full_tx);
        if let Err(panic) = worker.join() {
            std::panic::resume_unwind(panic);
        }
        read
    })
}

/// Reads `reader` (the entry `name`, declared `len` bytes) in pieces of `piece` bytes,
/// each into a buffer of that length that `take` gives and then handed to `give` with the
/// bytes filled (whole `unit`s; the last piece is shorter, maybe empty); stops early
/// where `take` has no buffer or `give` takes none (the other thread has stopped). Refuses
/// an entry of more or fewer bytes than declared.
fn pump(
    mut reader: impl Read,
    name: &str,
    len: usize,
    unit: usize,
    piece: usize,
    mut take: impl FnMut() -> Option<Vec<u8>>,
    mut give: impl FnMut(Vec<u8>, usize) -> bool,
) -> Result<()> {
    let mut done = 0usize;
    loop {
        let Some(mut buf) = take() else {
            return Ok(());
        };
        let mut filled = 0;
        while filled < piece {
            match reader.read(&mut buf[filled..]) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(entry_error(name, e)),
            }
        }
        done += filled;
        if done > len || filled % unit != 0 || (filled < piece && done != len) {
            let more = if done > len { "more" } else { "fewer" };
            return Err(bad(
                FORMAT,
                format!("{name} holds {more} bytes than the {len} declared"),
            ));
        }
        if !give(buf, filled) || filled < piece {
            return Ok(());
        }
    }
}

/// The MD5 of the archive entry `name`, streamed (see [`stream_entry`]).
fn entry_md5<R: Read + Seek>(archive: &mut ZipArchive<R>, name: &str) -> Result<String> {
    let size = archive
        .by_name(name)
        .map(|f| f.size())
        .map_err(|_| bad(FORMAT, format!("the archive has no {name}")))?;
    let len = usize::try_from(size).map_err(|_| bad(FORMAT, format!("{name} is too large")))?;
    let mut md5 = Md5::new();
    stream_entry(archive, name, len, 1, Some(&mut md5), |_| {})?;
    Ok(hex(&md5.finalize()))
}

/// A failed read of an archive entry; a zip CRC-32 mismatch said in those words.
fn entry_error(name: &str, e: std::io::Error) -> Error {
    if e.to_string().contains("checksum") {
        bad(
            FORMAT,
            format!("{name} fails its zip CRC-32 check: the archive is corrupt"),
        )
    } else {
        bad(FORMAT, format!("{name}: {e}"))
    }
}

/// Checks `data` against an MD5 checksum recorded in `main.xml` or `md5checksum.hex`
/// (hex, either case); an empty record is no checksum.
fn check_md5(what: &str, data: &[u8], recorded: Option<&str>) -> Result<()> {
    if recorded.is_some_and(|r| !r.trim().is_empty()) {
        compare_md5(what, &md5_hex(data), recorded)
    } else {
        Ok(())
    }
}

/// Compares the MD5 `got` (hex) of `what` with a recorded one (see [`check_md5`]).
fn compare_md5(what: &str, got: &str, recorded: Option<&str>) -> Result<()> {
    let Some(want) = recorded.map(str::trim).filter(|s| !s.is_empty()) else {
        return Ok(());
    };
    if got.eq_ignore_ascii_case(want) {
        Ok(())
    } else {
        Err(bad(
            FORMAT,
            format!("{what} fails its MD5 checksum (recorded {want}, computed {got}): the file is corrupt"),
        ))
    }
}

/// `main.xml`, read whole (so its CRC-32 is checked) up to [`MAX_XML`] bytes, through
/// [`zipped::member`](super::zipped::member) (its declared size checked before anything is
/// allocated, and against what it inflates to).
fn main_xml_text<R: Read + Seek>(archive: &mut ZipArchive<R>) -> Result<String> {
    let xml = super::zipped::member(archive, FORMAT, "main.xml", MAX_XML)?;
    String::from_utf8(xml).map_err(|_| bad(FORMAT, "main.xml is not UTF-8"))
}

/// The checksum file that `Record4/ChecksumFile` names: `HEX *NAME` lines, `main.xml`'s
/// checked here (where no name is given, the line is `main.xml`'s: the standard's choice,
/// while some writers record the payload's); the other lines returned as (entry, MD5) for
/// [`read`] to check as it streams those entries. Absent: nothing to check.
fn check_checksum_file<R: Read + Seek>(
    archive: &mut ZipArchive<R>,
    root: roxmltree::Node<'_, '_>,
    xml: &str,
) -> Result<Vec<(String, String)>> {
    let mut others = Vec::new();
    let Some(name) = text_at(root, &["Record4", "ChecksumFile"]).filter(|n| !n.is_empty()) else {
        return Ok(others);
    };
    let Ok(file) = archive.by_name(name) else {
        return Ok(others);
    };
    if file.size() > 4096 {
        return Err(bad(
            FORMAT,
            format!("{name} is larger than a checksum file"),
        ));
    }
    let mut text = String::new();
    file.take(4097)
        .read_to_string(&mut text)
        .map_err(|e| entry_error(name, e))?;
    for line in text.lines().filter(|l| !l.trim().is_empty()) {
        let mut parts = line.split_whitespace();
        let hex = parts.next().unwrap_or("");
        let target = parts
            .next()
            .map_or("main.xml", |t| t.trim_start_matches('*'));
        if target == "main.xml" {
            check_md5("main.xml", xml.as_bytes(), Some(hex))?;
        } else if !has_entry(archive, target) {
            return Err(bad(
                FORMAT,
                format!("{name} names {target}, which the archive lacks"),
            ));
        } else {
            others.push((target.to_string(), hex.to_string()));
        }
    }
    Ok(others)
}

fn has_entry<R: Read + Seek>(archive: &ZipArchive<R>, name: &str) -> bool {
    archive.index_for_name(name).is_some()
}

/// Reads an X3P file (see the module docs).
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    read_archive(ZipArchive::new(Cursor::new(bytes)).map_err(zip_error)?)
}

/// Reads the X3P file `file` where it is one (a zip archive that holds a `main.xml`),
/// without holding the file whole: its members are read from the file, the payload
/// streamed into the heights; `None` where it is not an X3P archive (the file is then read
/// whole and its format found as for any other).
pub(crate) fn read_from_file(file: &std::fs::File) -> Option<Result<Reading>> {
    let reader = std::io::BufReader::with_capacity(1 << 16, file);
    let archive = ZipArchive::new(reader).ok()?;
    if !has_entry(&archive, "main.xml") {
        return None;
    }
    Some(read_archive(archive))
}

/// Reads the X3P archive `archive` (see the module docs).
fn read_archive<R: Read + Seek>(mut archive: ZipArchive<R>) -> Result<Reading> {
    let xml = main_xml_text(&mut archive)?;
    let doc =
        roxmltree::Document::parse(&xml).map_err(|e| bad(FORMAT, format!("main.xml: {e}")))?;
    let root = doc.root_element();
    let mut checksums = check_checksum_file(&mut archive, root, &xml)?;
    let layout = layout(root)?;
    let count = layout.validate()?;
    let records = match &layout.payload {
        Some(name) => {
            // The payload's MD5s: main.xml's record and the checksum file's lines for it.
            let mut md5s: Vec<String> = layout.payload_md5.iter().cloned().collect();
            md5s.extend(take_lines_for(&mut checksums, name));
            payload(&mut archive, &layout, name, count, &md5s)?
        }
        None => inline_values(root, &layout, count)?,
    };
    for (target, hex) in &checksums {
        compare_md5(target, &entry_md5(&mut archive, target)?, Some(hex))?;
    }
    let spacing = absolute_spacing(&layout, &records)?;
    let mut values = records.z;
    if let Some(name) = &layout.valid_points {
        let bits = entry(&mut archive, name, count.div_ceil(8))?;
        check_md5(name, &bits, layout.valid_md5.as_deref())?;
        for (i, v) in values.iter_mut().enumerate() {
            if bits[i / 8] >> (i % 8) & 1 == 0 {
                *v = f64::NAN;
            }
        }
    }
    let heights = if layout.profile {
        Heights::Profile(Array1::from(values))
    } else {
        Heights::Areal(
            Array2::from_shape_vec((layout.ny, layout.nx), std::mem::take(&mut values))
                .map_err(|e| bad(FORMAT, e.to_string()))?,
        )
    };
    let size_y = (!layout.profile).then(|| spacing[1] * layout.ny as f64);
    Ok(Reading {
        format: FORMAT,
        channels: vec![Channel {
            name: "heights".into(),
            heights,
            size: [Some(spacing[0] * layout.nx as f64), size_y],
            unit: Some("m".into()),
            is_height: true,
        }],
    })
}

/// Removes from `lines` (entry, MD5) those for `name`; returns their MD5s.
fn take_lines_for(lines: &mut Vec<(String, String)>, name: &str) -> Vec<String> {
    let (mine, others) = std::mem::take(lines)
        .into_iter()
        .partition(|(target, _)| target == name);
    *lines = others;
    mine.into_iter().map(|(_, hex)| hex).collect()
}

/// The binary payload `name` of `count` records, streamed into the records' arrays (sized
/// once from the header, checked against the memory; no copy of the payload is held) and
/// checked against each MD5 of `md5s` (none: no MD5 is computed).
fn payload<R: Read + Seek>(
    archive: &mut ZipArchive<R>,
    layout: &Layout,
    name: &str,
    count: usize,
    md5s: &[String],
) -> Result<Records> {
    let width = layout.record_width();
    let len = count
        .checked_mul(width)
        .ok_or_else(|| bad(FORMAT, "the grid is larger than any memory"))?;
    let arrays = 1 + layout.absolute.iter().flatten().count();
    crate::memory::ensure_fits(
        &format!("reading {name} of an X3P file"),
        (count as u64).checked_mul(8 * arrays as u64),
    )?;
    let mut records = Records::with_capacity(count, layout.absolute.map(|a| a.is_some()));
    let mut md5 = md5s.iter().any(|m| !m.trim().is_empty()).then(Md5::new);
    stream_entry(archive, name, len, width, md5.as_mut(), |piece| {
        layout.decode(piece, &mut records)
    })?;
    if let Some(md5) = md5 {
        let got = hex(&md5.finalize());
        for want in md5s {
            compare_md5(name, &got, Some(want))?;
        }
    }
    Ok(records)
}

/// The values of an inline `DataList` (`Datum` elements; empty = undefined).
fn inline_values(root: roxmltree::Node<'_, '_>, layout: &Layout, count: usize) -> Result<Records> {
    let list = child(root, "Record3")
        .and_then(|r| child(r, "DataList"))
        .ok_or_else(|| bad(FORMAT, "Record3 has neither a DataLink nor a DataList"))?;
    let mut records = Records::default();
    for datum in list.children().filter(|c| c.tag_name().name() == "Datum") {
        if records.z.len() == count {
            return Err(bad(
                FORMAT,
                format!("DataList holds more than the {count} points of the grid"),
            ));
        }
        // `x;y;z` with the absolute axes' values first (an empty field is undefined).
        let text = datum.text().map(str::trim).unwrap_or("");
        let mut fields = text.split(';').map(str::trim);
        let parse = |f: Option<&str>| -> Result<f64> {
            match f {
                None | Some("") => Ok(f64::NAN),
                Some(t) => t
                    .parse::<f64>()
                    .map_err(|_| bad(FORMAT, format!("Datum {text:?} is not a number"))),
            }
        };
        for (k, c) in layout.absolute.iter().enumerate() {
            if let Some(c) = c {
                let v = c.value(parse(fields.next())?);
                if k == 0 {
                    records.x.push(v)
                } else {
                    records.y.push(v)
                }
            }
        }
        let z = parse(fields.next())?;
        records.z.push(if z.is_nan() { z } else { layout.scale(z) });
        if fields.next().is_some() {
            return Err(bad(
                FORMAT,
                format!("Datum {text:?} holds more values than axes"),
            ));
        }
    }
    if records.z.len() != count {
        return Err(bad(
            FORMAT,
            format!(
                "DataList holds {} points, the grid {count}",
                records.z.len()
            ),
        ));
    }
    Ok(records)
}

/// The coordinates of the absolute axes and the heights, point by point.
#[derive(Default)]
struct Records {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
}

impl Records {
    /// Room for `count` heights, and as many coordinates along each axis marked absolute.
    fn with_capacity(count: usize, absolute: [bool; 2]) -> Self {
        let room = |yes: bool| Vec::with_capacity(if yes { count } else { 0 });
        Records {
            x: room(absolute[0]),
            y: room(absolute[1]),
            z: Vec::with_capacity(count),
        }
    }
}

/// The largest distance of a stored coordinate from the uniform grid, in steps: coordinates
/// are written as f32 or rounded decimals, and a thousandth of a step is far below what
/// matters for the grid and well above f32 rounding on grids below a million points a side.
const GRID_TOLERANCE: f64 = 1e-3;

/// The spacing along x and y: the increments of incremental axes; for an absolute axis,
/// the step of the uniform grid its coordinates must form (x depending on the column only,
/// y on the row only, increasing; undefined coordinates skipped), or an error.
fn absolute_spacing(layout: &Layout, r: &Records) -> Result<[f64; 2]> {
    let mut spacing = layout.spacing;
    let (nx, ny) = (layout.nx, layout.ny);
    for (k, coords) in [&r.x, &r.y].into_iter().enumerate() {
        if layout.absolute[k].is_none() || (k == 1 && layout.profile) {
            continue;
        }
        let axis = ["x", "y"][k];
        let index = |i: usize| if k == 0 { i % nx } else { i / nx };
        let n = if k == 0 { nx } else { ny };
        // The step from a least-squares-free estimate: first and last defined indices.
        let defined: Vec<(usize, f64)> = coords
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_finite())
            .map(|(i, &v)| (index(i), v))
            .collect();
        let first = defined.iter().min_by_key(|p| p.0);
        let last = defined.iter().max_by_key(|p| p.0);
        let (Some(&(i0, v0)), Some(&(i1, v1))) = (first, last) else {
            return Err(bad(FORMAT, format!("no defined {axis} coordinate")));
        };
        let step = (v1 - v0) / (i1 as f64 - i0 as f64);
        if n < 2 || i1 == i0 || !(step.is_finite() && step > 0.0) {
            return Err(bad(
                FORMAT,
                format!("the {axis} coordinates do not increase along the grid"),
            ));
        }
        let origin = v0 - step * i0 as f64;
        let worst = defined
            .iter()
            .map(|&(i, v)| ((v - origin) / step - i as f64).abs())
            .fold(0.0, f64::max);
        if worst > GRID_TOLERANCE {
            return Err(bad(
                FORMAT,
                format!("the absolute {axis} coordinates are {worst:.3} steps off a uniform grid: not supported"),
            ));
        }
        spacing[k] = step;
    }
    Ok(spacing)
}

/// Hex MD5 in capitals, as X3P records it.
fn md5_hex(bytes: &[u8]) -> String {
    hex(&Md5::digest(bytes))
}

/// A digest in hex capitals.
fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02X}")).collect()
}

/// `main.xml` of a float64 map (`SUR`) of `nx × ny` points with spacings `dx, dy`.
fn main_xml(nx: usize, ny: usize, dx: f64, dy: f64, data_md5: &str) -> String {
    // `{:e}` prints the shortest decimal that reads back to the same f64.
    format!(
        r#"<?xml version="1.0" encoding="UTF-8" standalone="no" ?>
<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:schemaLocation="http://www.opengps.eu/2008/ISO5436_2 http://www.opengps.eu/2008/ISO5436_2/ISO5436_2.xsd">
  <Record1>
    <Revision>ISO5436 - 2000</Revision>
    <FeatureType>SUR</FeatureType>
    <Axes>
      <CX><AxisType>I</AxisType><DataType>D</DataType><Increment>{dx:e}</Increment><Offset>0</Offset></CX>
      <CY><AxisType>I</AxisType><DataType>D</DataType><Increment>{dy:e}</Increment><Offset>0</Offset></CY>
      <CZ><AxisType>A</AxisType><DataType>D</DataType></CZ>
    </Axes>
  </Record1>
  <Record2>
    <Date>1970-01-01T00:00:00</Date>
    <Instrument><Manufacturer>asperity</Manufacturer><Model>asperity</Model><Serial>not available</Serial><Version>{version}</Version></Instrument>
    <CalibrationDate>1970-01-01T00:00:00</CalibrationDate>
    <ProbingSystem><Type>Software</Type><Identification>asperity</Identification></ProbingSystem>
    <Comment/>
  </Record2>
  <Record3>
    <MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ></MatrixDimension>
    <DataLink><PointDataLink>bindata/data.bin</PointDataLink><MD5ChecksumPointData>{data_md5}</MD5ChecksumPointData></DataLink>
  </Record3>
  <Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4>
</p:ISO5436_2>
"#,
        version = env!("CARGO_PKG_VERSION"),
    )
}

/// An X3P archive of a map: float64 heights (metres, NaN for undefined points, written as
/// NaN), rows along y, sizes `[x, y]` in metres. Reading it back gives the same bits.
pub fn to_bytes(heights: ArrayView2<f64>, size: [f64; 2]) -> Result<Vec<u8>> {
    let (ny, nx) = heights.dim();
    if nx < 2 || ny < 2 {
        return Err(Error::invalid(
            "heights",
            format!("an X3P map needs at least 2 x 2 points, got {ny} x {nx}"),
        ));
    }
    if let Some(s) = size.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(Error::invalid(
            "size",
            format!(
                "must be positive and finite, got {}",
                crate::input::short_number(*s)
            ),
        ));
    }
    let mut data = Vec::new();
    data.try_reserve_exact(nx * ny * 8)
        .map_err(|_| Error::invalid("heights", "too large to encode in memory"))?;
    for v in heights.iter() {
        data.extend_from_slice(&v.to_le_bytes());
    }
    let xml = main_xml(
        nx,
        ny,
        size[0] / nx as f64,
        size[1] / ny as f64,
        &md5_hex(&data),
    );
    let checksum = format!("{} *main.xml\n", md5_hex(xml.as_bytes()));
    let options = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default())
        .large_file(data.len() as u64 >= u32::MAX as u64);
    let write = || -> zip::result::ZipResult<Vec<u8>> {
        let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
        zip.start_file("main.xml", options)?;
        zip.write_all(xml.as_bytes())?;
        zip.start_file("md5checksum.hex", options)?;
        zip.write_all(checksum.as_bytes())?;
        // The payload of doubles barely compresses: stored, to write large maps quickly.
        zip.start_file(
            "bindata/data.bin",
            options.compression_method(CompressionMethod::Stored),
        )?;
        zip.write_all(&data)?;
        Ok(zip.finish()?.into_inner())
    };
    write().map_err(|e| Error::invalid("heights", format!("X3P archive: {e}")))
}

/// Writes a map as an X3P file, atomically (see [`to_bytes`]).
pub fn write(path: &Path, force: bool, heights: ArrayView2<f64>, size: [f64; 2]) -> Result<()> {
    let bytes = to_bytes(heights, size)?;
    crate::io::write_bytes(path, force, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::test_files::{assert_close, folder, fuzz, record, reference};

    #[test]
    fn x3p_matches_the_reference() {
        let Some(dir) = folder() else { return };
        let name = "x3p-2.x3p";
        let bytes = std::fs::read(dir.join(name)).unwrap();
        assert!(sniff(&bytes));
        let reading = read(&bytes).unwrap();
        let c = &reading.channels[0];
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        // The reference is [x, y]; ours (row y, col x): h[(y, x)] = reference[x, y].
        let reference = reference(&dir, name)
            .into_dimensionality::<ndarray::Ix2>()
            .unwrap();
        assert_eq!(reference.dim(), (h.ncols(), h.nrows()));
        for ((x, y), v) in reference.indexed_iter() {
            assert_eq!(h[(y, x)].to_bits(), v.to_bits(), "{name} at x {x}, y {y}");
        }
        let record = record(&dir, name);
        for axis in 0..2 {
            let want = record["physical_sizes_m"][axis].as_f64().unwrap();
            assert_close(c.size[axis].unwrap(), want, 1e-12, name);
        }
    }

    #[test]
    fn writer_round_trip_is_bit_exact() {
        let h = Array2::from_shape_fn((5, 7), |(r, c)| {
            if (r, c) == (2, 3) {
                f64::NAN
            } else {
                ((r * 7 + c) as f64 * 0.37).sin() * 1.234_567_891e-7
            }
        });
        let size = [7.0e-6 / 3.0, 1.1e-5];
        let bytes = to_bytes(h.view(), size).unwrap();
        assert!(sniff(&bytes));
        let r = read(&bytes).unwrap();
        let Heights::Areal(back) = &r.channels[0].heights else {
            panic!()
        };
        for (a, b) in back.iter().zip(h.iter()) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
        assert_close(r.channels[0].size[0].unwrap(), size[0], 1e-15, "size x");
        assert_close(r.channels[0].size[1].unwrap(), size[1], 1e-15, "size y");
        // Same input, same bytes.
        assert_eq!(bytes, to_bytes(h.view(), size).unwrap());
        fuzz(&bytes, read);
    }

    #[test]
    fn inline_data_list_and_integer_scaling() {
        let xml = r#"<?xml version="1.0"?><p:ISO5436_2 xmlns:p="x"><Record1><FeatureType>SUR</FeatureType>
            <Axes><CX><AxisType>I</AxisType><Increment>1e-6</Increment></CX>
            <CY><AxisType>I</AxisType><Increment>2e-6</Increment></CY>
            <CZ><AxisType>A</AxisType><DataType>L</DataType><Increment>1e-9</Increment><Offset>1e-6</Offset></CZ></Axes></Record1>
            <Record3><MatrixDimension><SizeX>2</SizeX><SizeY>2</SizeY><SizeZ>1</SizeZ></MatrixDimension>
            <DataList><Datum>1</Datum><Datum>-2</Datum><Datum/><Datum>4</Datum></DataList></Record3></p:ISO5436_2>"#;
        let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
        zip.start_file("main.xml", SimpleFileOptions::default())
            .unwrap();
        zip.write_all(xml.as_bytes()).unwrap();
        let bytes = zip.finish().unwrap().into_inner();
        let r = read(&bytes).unwrap();
        let Heights::Areal(h) = &r.channels[0].heights else {
            panic!()
        };
        assert_close(h[(0, 1)], 1e-6 - 2e-9, 1e-15, "offset + increment · raw");
        assert!(h[(1, 0)].is_nan());
        assert_eq!(r.channels[0].size, [Some(2e-6), Some(4e-6)]);
    }

    /// An X3P archive in the standard's layout whose CX (f64) and CY (f32) axes are absolute:
    /// each point's record is x, y, z; the coordinates are `xs[col]`, `ys[row]`.
    fn absolute_axes_file(xs: &[f64], ys: &[f32], z: &[f64], inline: bool) -> Vec<u8> {
        let (nx, ny) = (xs.len(), ys.len());
        let mut data = Vec::new();
        let mut list = String::new();
        for (i, &h) in z.iter().enumerate() {
            data.extend_from_slice(&xs[i % nx].to_le_bytes());
            data.extend_from_slice(&ys[i / nx].to_le_bytes());
            data.extend_from_slice(&h.to_le_bytes());
            list += &format!("<Datum>{};{};{h}</Datum>", xs[i % nx], ys[i / nx]);
        }
        let link = if inline {
            format!("<DataList>{list}</DataList>")
        } else {
            "<DataLink><PointDataLink>bindata/data.bin</PointDataLink></DataLink>".to_string()
        };
        let xml = format!(
            r#"<?xml version="1.0"?><p:ISO5436_2 xmlns:p="x"><Record1><Revision>ISO5436 - 2000</Revision><FeatureType>SUR</FeatureType>
            <Axes><CX><AxisType>A</AxisType><DataType>D</DataType></CX>
            <CY><AxisType>A</AxisType><DataType>F</DataType><Increment>1e-6</Increment></CY>
            <CZ><AxisType>A</AxisType><DataType>D</DataType></CZ></Axes></Record1>
            <Record3><MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ></MatrixDimension>{link}</Record3></p:ISO5436_2>"#
        );
        let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
        let options = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
        zip.start_file("main.xml", options).unwrap();
        zip.write_all(xml.as_bytes()).unwrap();
        if !inline {
            zip.start_file("bindata/data.bin", options).unwrap();
            zip.write_all(&data).unwrap();
        }
        zip.finish().unwrap().into_inner()
    }

    #[test]
    fn absolute_lateral_axes_on_a_uniform_grid_are_read() {
        // x = 5 µm + 2 µm · col (stored in metres), y = (3 + 0.5 · row) µm (stored in µm
        // as f32 with Increment 1e-6).
        let xs = [5e-6, 7e-6, 9e-6];
        let ys = [3.0f32, 3.5];
        let z = [1e-9, 2e-9, f64::NAN, 4e-9, 5e-9, 6e-9];
        for inline in [false, true] {
            let bytes = absolute_axes_file(&xs, &ys, &z, inline);
            let r = read(&bytes).unwrap();
            let c = &r.channels[0];
            let Heights::Areal(h) = &c.heights else {
                panic!()
            };
            assert_eq!(h.dim(), (2, 3));
            for (g, w) in h.iter().zip(z) {
                assert!(g.is_nan() && w.is_nan() || g == &w, "{g} vs {w}");
            }
            let [sx, sy] = c.size;
            assert_close(sx.unwrap(), 6e-6, 1e-12, "x: 3 steps of 2 µm");
            assert_close(sy.unwrap(), 1e-6, 1e-6, "y: 2 steps of 0.5 µm (f32)");
        }
    }

    #[test]
    fn absolute_axes_off_a_uniform_grid_or_truncated_are_refused() {
        let z = [0.0; 6];
        let bytes = absolute_axes_file(&[0.0, 1e-6, 3e-6], &[0.0, 1.0], &z, false);
        let err = read(&bytes).unwrap_err().to_string();
        assert!(err.contains("off a uniform grid"), "{err}");
        let bytes = absolute_axes_file(&[2e-6, 1e-6, 0.0], &[0.0, 1.0], &z, true);
        let err = read(&bytes).unwrap_err().to_string();
        assert!(err.contains("do not increase"), "{err}");
        let good = absolute_axes_file(&[0.0, 1e-6, 2e-6], &[0.0, 1.0], &z, false);
        for cut in (0..good.len()).step_by(7) {
            assert!(read(&good[..cut]).is_err(), "cut at {cut}");
        }
        fuzz(&good, read);
    }

    /// The archive `bytes` with each entry passed through `edit(name, data)`; with
    /// `rehash`, `md5checksum.hex` is rewritten for the edited `main.xml`.
    fn rezip(bytes: &[u8], rehash: bool, edit: impl Fn(&str, Vec<u8>) -> Vec<u8>) -> Vec<u8> {
        let mut archive = ZipArchive::new(Cursor::new(bytes)).unwrap();
        let mut out = ZipWriter::new(Cursor::new(Vec::new()));
        let mut xml = Vec::new();
        for i in 0..archive.len() {
            let mut file = archive.by_index(i).unwrap();
            let name = file.name().to_string();
            let mut data = Vec::new();
            file.read_to_end(&mut data).unwrap();
            let data = edit(&name, data);
            if name == "main.xml" {
                xml = data.clone();
            }
            let data = if rehash && name == "md5checksum.hex" {
                format!("{} *main.xml\n", md5_hex(&xml)).into_bytes()
            } else {
                data
            };
            out.start_file(name, SimpleFileOptions::default()).unwrap();
            out.write_all(&data).unwrap();
        }
        out.finish().unwrap().into_inner()
    }

    fn map_bytes() -> Vec<u8> {
        let h = Array2::from_shape_fn((6, 5), |(r, c)| ((r * 5 + c) as f64).cos() * 1e-7);
        to_bytes(h.view(), [5e-6, 6e-6]).unwrap()
    }

    #[test]
    fn a_corrupted_payload_fails_its_checksums() {
        // One bit flipped in the stored payload: the zip CRC-32 fails.
        let bytes = map_bytes();
        let mut archive = ZipArchive::new(Cursor::new(&bytes[..])).unwrap();
        let payload = archive
            .by_name("bindata/data.bin")
            .unwrap()
            .data_start()
            .unwrap() as usize
            + 40;
        let mut flipped = bytes.clone();
        flipped[payload] ^= 0x10;
        let err = read(&flipped).unwrap_err().to_string();
        assert!(err.contains("CRC-32"), "{err}");
        // The CRC-32 made consistent (re-zipped) but MD5ChecksumPointData not: refused.
        let edited = rezip(&bytes, false, |name, mut data| {
            if name.ends_with("data.bin") {
                data[17] ^= 0x01;
            }
            data
        });
        let err = read(&edited).unwrap_err().to_string();
        assert!(err.contains("MD5"), "{err}");
        // main.xml that no longer matches md5checksum.hex: refused.
        let edited = rezip(&bytes, false, |name, data| {
            if name == "main.xml" {
                String::from_utf8(data)
                    .unwrap()
                    .replace("<Comment/>", "<Comment>x</Comment>")
                    .into_bytes()
            } else {
                data
            }
        });
        let err = read(&edited).unwrap_err().to_string();
        assert!(err.contains("main.xml fails its MD5"), "{err}");
    }

    #[test]
    fn payloads_of_many_pieces_are_read_through_the_second_thread() {
        // 300 × 400 float64 (3.7 pieces of 256 KiB) and 256 × 256 (exactly 2 pieces, so a
        // last empty read): stored and deflated, bit for bit the map written, MD5 checked.
        for (ny, nx) in [(300, 400), (256, 256)] {
            let h = Array2::from_shape_fn((ny, nx), |(r, c)| {
                ((r * nx + c) as f64 * 0.731).sin() * 3.2e-7
            });
            let stored = to_bytes(h.view(), [1e-3, 1e-3]).unwrap();
            let deflated = rezip(&stored, false, |_, data| data);
            assert!(deflated.len() < stored.len() + 4096);
            for bytes in [&stored, &deflated] {
                let r = read(bytes).unwrap();
                let Heights::Areal(back) = &r.channels[0].heights else {
                    panic!()
                };
                assert!(back.iter().zip(&h).all(|(a, b)| a.to_bits() == b.to_bits()));
            }
            // One byte changed in the last piece (CRC-32 made consistent by the re-zip):
            // the MD5, run on the second thread, refuses it.
            let edited = rezip(&stored, false, |name, mut data| {
                if name.ends_with("data.bin") {
                    assert!(data.len() >= 2 * PIECE);
                    let i = data.len() - 12_345;
                    data[i] ^= 0x40;
                }
                data
            });
            let err = read(&edited).unwrap_err().to_string();
            assert!(err.contains("MD5"), "{err}");
        }
    }

    #[test]
    fn a_deflated_payload_with_a_flipped_bit_is_refused() {
        let Some(dir) = folder() else { return };
        // x3p-2.x3p's payload is deflated: every single-bit flip inside it is refused
        // (a deflate error, or the CRC-32 / MD5 of what inflates).
        let bytes = std::fs::read(dir.join("x3p-2.x3p")).unwrap();
        let mut archive = ZipArchive::new(Cursor::new(&bytes[..])).unwrap();
        let file = archive.by_name("bindata/data.bin").unwrap();
        let start = file.data_start().unwrap() as usize;
        let compressed = file.compressed_size() as usize;
        drop(file);
        let mut copy = bytes.clone();
        for k in 0..40 {
            let i = start + 200 + k * (compressed - 400) / 40;
            copy[i] ^= 1 << (k % 8);
            assert!(
                read(&copy).is_err(),
                "bit {} of byte {i} flipped was read",
                k % 8
            );
            copy[i] = bytes[i];
        }
    }

    #[test]
    fn a_payload_that_does_not_match_the_header_is_refused() {
        let bytes = map_bytes();
        // The header says float32 where the payload holds float64: twice the bytes.
        let edited = rezip(&bytes, true, |name, data| {
            if name == "main.xml" {
                String::from_utf8(data)
                    .unwrap()
                    .replace(
                        "<CZ><AxisType>A</AxisType><DataType>D",
                        "<CZ><AxisType>A</AxisType><DataType>F",
                    )
                    .into_bytes()
            } else {
                data
            }
        });
        let err = read(&edited).unwrap_err().to_string();
        assert!(err.contains("holds 240 bytes where"), "{err}");
        // A payload longer than the grid (one more row of heights): refused.
        let edited = rezip(&bytes, true, |name, data| {
            if name == "main.xml" {
                String::from_utf8(data)
                    .unwrap()
                    .replace("<SizeY>6</SizeY>", "<SizeY>5</SizeY>")
                    .into_bytes()
            } else {
                data
            }
        });
        let err = read(&edited).unwrap_err().to_string();
        assert!(err.contains("need 200"), "{err}");
    }

    #[test]
    fn valid_points_mask_and_scaled_integers_match_the_reference() {
        // openGPS sample 4: int16 heights with increment and offset, a valid-points bit
        // array (in `DataLink`) marking one point undefined, lower-case MD5s.
        use super::super::testkit::{check_shared, Expect};
        let expect = Expect {
            channel_names: false, // the peer names the channel `Default`, we `heights`
            ..Expect::default()
        };
        check_shared("topographies-3", "openfmc-ISO5436-sample4_bin.x3p", expect);
    }

    #[test]
    fn surface_topography_written_files_match_the_reference() {
        // SurfaceTopography's own writer records the payload's MD5 in md5checksum.hex.
        use super::super::testkit::{check_shared, Expect};
        for name in ["st-written-1.x3p", "st-written-2.x3p"] {
            let expect = Expect {
                channel_names: false,
                ..Expect::default()
            };
            check_shared("topographies-2", name, expect);
        }
    }

    #[test]
    fn fuzzed_x3p_never_panics() {
        let Some(dir) = folder() else { return };
        let bytes = std::fs::read(dir.join("x3p-2.x3p")).unwrap();
        fuzz(&bytes, read);
        assert!(read(b"PK\x03\x04 not really").is_err());
    }

    /// An archive of `members` (name, bytes), each deflated.
    fn archive(members: &[(&str, &[u8])]) -> Vec<u8> {
        let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
        let options = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
        for (name, bytes) in members {
            zip.start_file(*name, options).unwrap();
            zip.write_all(bytes).unwrap();
        }
        zip.finish().unwrap().into_inner()
    }

    /// Rewrites the uncompressed size that the local and central headers of member `name`
    /// declare.
    fn declare_size(zip: &mut [u8], name: &str, size: u32) {
        let named = |zip: &[u8], i: usize, at: usize, len_at: usize| {
            let len = u16::from_le_bytes([zip[i + len_at], zip[i + len_at + 1]]) as usize;
            zip.get(i + at..i + at + len) == Some(name.as_bytes())
        };
        for i in 0..zip.len().saturating_sub(46) {
            if zip[i..].starts_with(b"PK\x03\x04") && named(zip, i, 30, 26) {
                zip[i + 22..i + 26].copy_from_slice(&size.to_le_bytes());
            }
            if zip[i..].starts_with(b"PK\x01\x02") && named(zip, i, 46, 28) {
                zip[i + 24..i + 28].copy_from_slice(&size.to_le_bytes());
            }
        }
    }

    /// Issue 33: zip bombs in an X3P file are refused in one line, before anything of
    /// their declared size is allocated: a `main.xml` that inflates past its bound, a
    /// payload whose header declares the 3.2 GB its grid needs from a few compressed bytes,
    /// and a payload that inflates beyond what it declares.
    #[test]
    fn zip_bombs_are_refused_without_allocating() {
        let one_line = |bytes: &[u8], needle: &str| {
            let err = read(bytes).unwrap_err().to_string();
            assert!(err.contains(needle) && err.lines().count() == 1, "{err}");
        };
        // 17 MiB of spaces deflate to about 17 kB.
        let mut xml = main_xml(2, 2, 1e-6, 1e-6, "").into_bytes();
        xml.resize((MAX_XML + (1 << 20)) as usize, b' ');
        one_line(&archive(&[("main.xml", &xml)]), "main.xml declares");
        // 20000 x 20000 doubles declared; 4 kB of zeros stored.
        let xml = main_xml(20_000, 20_000, 1e-6, 1e-6, "");
        let zeros = vec![0u8; 4096];
        let mut bomb = archive(&[("main.xml", xml.as_bytes()), ("bindata/data.bin", &zeros)]);
        declare_size(&mut bomb, "bindata/data.bin", 3_200_000_000);
        one_line(&bomb, "cannot come from");
        // A 2 x 2 grid (32 bytes) whose payload inflates to 1 MB while declaring 32.
        let xml = main_xml(2, 2, 1e-6, 1e-6, "");
        let mut more = archive(&[
            ("main.xml", xml.as_bytes()),
            ("bindata/data.bin", &vec![0u8; 1 << 20]),
        ]);
        declare_size(&mut more, "bindata/data.bin", 32);
        let err = read(&more).unwrap_err().to_string();
        assert_eq!(err.lines().count(), 1, "{err}");
        // Every member declaring 4 GiB, and sizes altered at random (issue 34).
        super::super::testkit::assert_zip_sizes_robust(
            &map_bytes(),
            read,
            std::time::Duration::from_millis(300),
        );
    }
}
