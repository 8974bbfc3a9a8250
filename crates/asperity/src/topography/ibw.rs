//! Igor Pro **binary wave** files, version 5 (`.ibw`), as written by Asylum Research AFMs.
//!
//! A 64-byte `BinHeader5` (the version `5` in the first two bytes also gives the byte
//! order; then the sizes of the wave record, formula, note, extended data units, the four
//! extended dimension units and the four dimension-label blocks), a 320-byte
//! `WaveHeader5` (`npnts` at 76, the number type at 80, `nDim[4]` at 132, the scale steps
//! `sfA[4]` at 148, `dataUnits` at 212 and `dimUnits[4][4]` at 216), then the data from
//! byte 384, column-major (x fastest, then y, then the layer). After the wave record come
//! the formula, the note, the extended units and the dimension labels, 32 bytes each, the
//! first of each block naming the dimension itself. Each layer (dimension 2) is a channel
//! named by its label; its values are in the data unit (heights in metres where that is a
//! length); the sizes are `nDim · sfA` in the x and y units. Lines are stored from the
//! bottom up; rows are returned top down, as the reference reader does. Facts from
//! WaveMetrics' technical note PTN003 and the shared file `spot_1-1000nm.ibw` with its
//! reference reading; versions other than 5 and complex or 8-bit/64-bit integer data are
//! refused.

use super::bytes::{
    areal, bad, fixed_text, flip_rows, length_unit, samples, Cursor, Endian, Sample,
};
use super::{canonical_unit, Channel, Heights, Reading};
use crate::Result;

const FORMAT: &str = "ibw";
const BIN_HEADER: usize = 64;
const DATA: usize = BIN_HEADER + 320;
const LABEL: usize = 32;

/// Version 5 in either byte order, and a wave record that fits its own header.
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    bytes.len() >= DATA && matches!(&bytes[..2], [5, 0] | [0, 5])
}

/// The block sizes of the `BinHeader5`: wave record, formula, note, extended data units,
/// extended dimension units and dimension labels.
struct Sizes {
    wave: usize,
    before_labels: usize,
    labels: [usize; 4],
    /// Sparse indices and the two option blocks, after the labels.
    after_labels: usize,
}

fn sizes(c: &mut Cursor, e: Endian) -> Result<Sizes> {
    let mut size = |what: &str| -> Result<usize> {
        let v = c.i32(e)?;
        usize::try_from(v).map_err(|_| bad(FORMAT, format!("negative {what} size {v}")))
    };
    let wave = size("wave")?;
    let mut before_labels = 0usize;
    for what in [
        "formula",
        "note",
        "data units",
        "x units",
        "y units",
        "z units",
        "t units",
    ] {
        before_labels = before_labels.saturating_add(size(what)?);
    }
    let labels = [
        size("labels")?,
        size("labels")?,
        size("labels")?,
        size("labels")?,
    ];
    let mut after_labels = 0usize;
    for what in ["sparse indices", "options", "options"] {
        after_labels = after_labels.saturating_add(size(what)?);
    }
    Ok(Sizes {
        after_labels,
        wave,
        before_labels,
        labels,
    })
}

fn sample(kind: i16) -> Result<Sample> {
    Ok(match kind {
        2 => Sample::F32,
        4 => Sample::F64,
        0x10 => Sample::I16,
        0x20 => Sample::I32,
        0x48 => Sample::U8,
        0x50 => Sample::U16,
        other => {
            return Err(bad(
                FORMAT,
                format!(
                "number type {other:#x} is not supported (complex, 8- or 64-bit integer, or text)"
            ),
            ))
        }
    })
}

/// The layer labels (dimension 2), if the file has them.
fn layer_names(bytes: &[u8], s: &Sizes, layers: usize) -> Vec<String> {
    let start = BIN_HEADER
        .saturating_add(s.wave)
        .saturating_add(s.before_labels)
        .saturating_add(s.labels[0])
        .saturating_add(s.labels[1]);
    let block = bytes
        .get(start..start.saturating_add(s.labels[2]))
        .unwrap_or(&[]);
    let names: Vec<String> = block.chunks_exact(LABEL).skip(1).map(fixed_text).collect();
    (0..layers)
        .map(|k| match names.get(k) {
            Some(n) if !n.is_empty() => n.clone(),
            _ => format!("layer {k}"),
        })
        .collect()
}

/// `nDim[4]` of the wave header: one or more 2D images (`nx × ny × layers`).
fn dimensions(c: &mut Cursor, e: Endian) -> Result<[usize; 4]> {
    let mut dims = [0usize; 4];
    for d in &mut dims {
        let v = c.i32(e)?;
        *d = usize::try_from(v).map_err(|_| bad(FORMAT, format!("negative dimension {v}")))?;
    }
    if dims[0] == 0 || dims[1] == 0 || dims[3] > 1 {
        return Err(bad(
            FORMAT,
            format!("dimensions {dims:?}: not one or more 2D images"),
        ));
    }
    Ok(dims)
}

/// Reads a version-5 binary wave (see the module docs).
/// Refuses a file whose header's blocks run past its end, or whose wave record is shorter
/// than the `total` samples of `sample` it declares.
fn check_blocks(bytes: &[u8], s: &Sizes, total: usize, sample: Sample) -> Result<()> {
    let declared = [
        s.wave,
        s.before_labels,
        s.labels.iter().sum(),
        s.after_labels,
    ]
    .iter()
    .try_fold(BIN_HEADER, |acc, &b| acc.checked_add(b));
    if declared.is_none_or(|end| end > bytes.len()) {
        return Err(bad(
            FORMAT,
            "truncated: the header's blocks run past the end of the file",
        ));
    }
    if total
        .checked_mul(sample.size())
        .is_none_or(|d| d + 320 > s.wave)
    {
        return Err(bad(
            FORMAT,
            "the wave record is shorter than the data its header declares",
        ));
    }
    Ok(())
}

pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    if !sniff(bytes) {
        return Err(bad(FORMAT, "not an Igor binary wave of version 5"));
    }
    let e = if bytes[0] == 5 {
        Endian::Little
    } else {
        Endian::Big
    };
    let mut c = Cursor::new(FORMAT, bytes);
    c.seek(4)?;
    let s = sizes(&mut c, e)?;
    c.seek(80)?;
    let sample = sample(c.i16(e)?)?;
    c.seek(132)?;
    let dims = dimensions(&mut c, e)?;
    let (nx, ny, layers) = (dims[0], dims[1], dims[2].max(1));
    let steps = [c.f64(e)?, c.f64(e)?];
    c.seek(212)?;
    let data_unit = fixed_text(c.take(4)?);
    let dim_units = [fixed_text(c.take(4)?), fixed_text(c.take(4)?)];
    let n = nx
        .checked_mul(ny)
        .ok_or_else(|| bad(FORMAT, "the image is too large"))?;
    let total = n
        .checked_mul(layers)
        .ok_or_else(|| bad(FORMAT, "the wave is too large"))?;
    check_blocks(bytes, &s, total, sample)?;
    let values = samples(FORMAT, bytes, DATA, total, sample, e)?;
    let metres = length_unit(&data_unit).map(|(_, f)| f);
    let size = |k: usize| {
        let per = length_unit(&dim_units[k]).map(|(_, f)| f)?;
        let s = steps[k] * dims[k] as f64 * per;
        crate::is_positive_finite(s).then_some(s)
    };
    let names = layer_names(bytes, &s, layers);
    let mut channels = Vec::with_capacity(layers);
    // One layer (the usual image) is scaled in place, several are split into copies.
    let layers_values: Vec<Vec<f64>> = if layers == 1 {
        vec![values]
    } else {
        values.chunks_exact(n).map(<[f64]>::to_vec).collect()
    };
    for (mut layer, name) in layers_values.into_iter().zip(names) {
        layer.iter_mut().for_each(|v| *v *= metres.unwrap_or(1.0));
        let mut heights = areal(FORMAT, ny, nx, layer)?;
        flip_rows(&mut heights);
        channels.push(Channel {
            name,
            heights: Heights::Areal(heights),
            size: [size(0), size(1)],
            unit: (!data_unit.is_empty()).then(|| canonical_unit(&data_unit)),
            is_height: metres.is_some(),
        });
    }
    Ok(Reading {
        format: FORMAT,
        channels,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testkit::{assert_robust, check_shared, set_dir};
    use super::*;
    use std::time::Duration;

    #[test]
    fn reads_the_real_file_to_the_reference() {
        // spot_1-1000nm.ibw: 256 × 256 × 8 layers of f32, data unit m.
        check_shared("topographies-3", "spot_1-1000nm.ibw", Default::default());
    }

    /// A wave of `nx × ny × layers` i16 samples in the version-5 layout, labels included.
    fn wave(nx: i32, ny: i32, layers: i32, data: &[i16], labels: &[&str]) -> Vec<u8> {
        let wave_size = 320 + 2 * data.len() as i32;
        let label_bytes = LABEL as i32 * (labels.len() as i32 + 1);
        let mut f = vec![0u8; DATA];
        f[..2].copy_from_slice(&5i16.to_le_bytes());
        f[4..8].copy_from_slice(&wave_size.to_le_bytes());
        f[44..48].copy_from_slice(&label_bytes.to_le_bytes()); // dimLabelsSize[2]
        f[76..80].copy_from_slice(&(nx * ny * layers).to_le_bytes());
        f[80..82].copy_from_slice(&0x10i16.to_le_bytes());
        for (k, d) in [nx, ny, layers, 0].iter().enumerate() {
            f[132 + 4 * k..136 + 4 * k].copy_from_slice(&d.to_le_bytes());
        }
        f[148..156].copy_from_slice(&1e-6f64.to_le_bytes());
        f[156..164].copy_from_slice(&2e-6f64.to_le_bytes());
        f[212..214].copy_from_slice(b"nm");
        f[216..218].copy_from_slice(b"m\0");
        f[220..222].copy_from_slice(b"m\0");
        f.extend(data.iter().flat_map(|v| v.to_le_bytes()));
        f.extend(vec![0u8; LABEL]);
        for l in labels {
            let mut b = l.as_bytes().to_vec();
            b.resize(LABEL, 0);
            f.extend(b);
        }
        f
    }

    #[test]
    fn a_small_wave_in_the_format_layout() {
        let data = [1i16, 2, 3, 4, 5, 6, 10, 20, 30, 40, 50, 60];
        let r = read(&wave(3, 2, 2, &data, &["Height", "Phase"])).unwrap();
        let names: Vec<&str> = r.channels.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["Height", "Phase"]);
        let c = &r.channels[1];
        assert_eq!(c.size, [Some(3e-6), Some(4e-6)]);
        assert_eq!(c.unit.as_deref(), Some("nm"));
        let Heights::Areal(h) = &c.heights else {
            panic!()
        };
        // x fastest, first stored line at the bottom: row 0 is the second stored line.
        assert_eq!(h.dim(), (2, 3));
        assert!((h[(0, 0)] - 40e-9).abs() < 1e-20 && (h[(1, 2)] - 30e-9).abs() < 1e-20);
        // A wave record longer than the file: refused.
        let f = wave(3, 2, 2, &data, &["Height", "Phase"]);
        assert!(read(&f[..f.len() - 3]).is_err());
        assert!(read(&f[..DATA + 20]).is_err());
        assert!(read(&wave(3, 2, 2, &data[..11], &[])).is_err());
    }

    #[test]
    fn survives_truncation_corruption_and_a_wrong_signature() {
        let Some(dir) = set_dir("topographies-3") else {
            return;
        };
        let bytes = std::fs::read(dir.join("spot_1-1000nm.ibw")).unwrap();
        // The file carries 131,578 bytes after every block its header declares (Asylum's
        // own trailer, not part of the wave), which no reader can tell from a truncation:
        // the loop runs on the declared part, the 64-byte BinHeader5 and its 14 block sizes.
        let declared = BIN_HEADER
            + (0..14)
                .map(|k| {
                    let b: [u8; 4] = bytes[4 + 4 * k..8 + 4 * k].try_into().unwrap();
                    i32::from_le_bytes(b) as usize
                })
                .sum::<usize>();
        assert_eq!(bytes.len() - declared, 131_578);
        assert!(read(&bytes[..declared]).is_ok());
        assert_robust(
            &bytes[..declared],
            sniff,
            read,
            DATA,
            Some(2),
            Duration::from_millis(300),
        );
    }
}
