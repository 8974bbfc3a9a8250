//! HDF5 files (`.h5`, `.hdf5`; also how the contact-mechanics challenge surface is
//! distributed).
//!
//! The container is read by the HDF5 C library (crate `hdf5-metno`, the optional feature
//! `hdf5`; Debian package `libhdf5-dev`). Without the feature an HDF5 file is still
//! recognised, and refused with one line naming the feature.
//!
//! Generic HDF5 carries no units or physical sizes: every two-dimensional numeric dataset
//! (integers or floats, any depth of groups, in the order of their names) is a channel
//! named by its path without the leading `/`; its first index runs along x (as
//! SurfaceTopography's `H5Reader` reads it), so our map is the dataset's transpose; the
//! size must be given. The file is opened from memory (HDF5's core driver with a file
//! image, never a path on disk), only hard links are followed (an external link would open
//! another file), and no more values are read than the file's bytes can hold (uncompressed)
//! or a deflate stream can expand to (compressed).

use super::{bad, Reading};
use crate::Result;

pub(crate) const FORMAT: &str = "hdf5";

/// The 8-byte HDF5 signature.
const SIGNATURE: &[u8; 8] = b"\x89HDF\r\n\x1a\n";

/// Where the superblock starts: offset 0, or 512, 1024, 2048, ... after a user block.
fn superblock(bytes: &[u8]) -> Option<usize> {
    let mut at = 0usize;
    while at + SIGNATURE.len() <= bytes.len() {
        if &bytes[at..at + SIGNATURE.len()] == SIGNATURE {
            return Some(at);
        }
        at = if at == 0 { 512 } else { at.checked_mul(2)? };
    }
    None
}

/// An HDF5 signature at 0 or after a user block (a power of two from 512).
pub(crate) fn sniff(bytes: &[u8]) -> bool {
    superblock(bytes).is_some()
}

/// The end of the file the superblock records (base address + end-of-file address), checked
/// before the library sees the bytes: a truncated file is named as such.
fn check_length(bytes: &[u8]) -> Result<()> {
    let at = superblock(bytes).ok_or_else(|| bad(FORMAT, "no HDF5 signature"))?;
    let sb = &bytes[at..];
    let truncated = || bad(FORMAT, "the file ends inside its superblock (truncated)");
    let version = *sb.get(8).ok_or_else(truncated)?;
    // Size of offsets, and where the base and end-of-file addresses are.
    let (offsets, base_at) = match version {
        0 => (*sb.get(13).ok_or_else(truncated)?, 24),
        1 => (*sb.get(13).ok_or_else(truncated)?, 28),
        2 | 3 => (*sb.get(9).ok_or_else(truncated)?, 12),
        v => return Err(bad(FORMAT, format!("superblock version {v} is not known"))),
    };
    let width = match offsets {
        2 | 4 | 8 => offsets as usize,
        o => return Err(bad(FORMAT, format!("{o}-byte file offsets are not HDF5's"))),
    };
    let eof_at = base_at + 2 * width;
    let address = |from: usize| -> Result<u64> {
        let field = sb.get(from..from + width).ok_or_else(truncated)?;
        Ok(field
            .iter()
            .rev()
            .fold(0u64, |acc, &b| (acc << 8) | u64::from(b)))
    };
    let base = address(base_at)?;
    let eof = address(eof_at)?;
    let end = base.saturating_add(eof);
    if end > bytes.len() as u64 {
        return Err(bad(
            FORMAT,
            format!(
                "the superblock records {end} bytes but the file has {} (truncated)",
                bytes.len()
            ),
        ));
    }
    Ok(())
}

/// Reads a generic HDF5 file.
pub(crate) fn read(bytes: &[u8]) -> Result<Reading> {
    check_length(bytes)?;
    imp::read(bytes)
}

#[cfg(not(feature = "hdf5"))]
mod imp {
    use super::{bad, Reading, FORMAT};
    use crate::Result;

    pub(super) fn read(_bytes: &[u8]) -> Result<Reading> {
        Err(bad(
            FORMAT,
            "an HDF5 file: this asperity was built without the `hdf5` \
             feature; rebuild with `--features hdf5` (needs the HDF5 library, e.g. Debian \
             libhdf5-dev)",
        ))
    }
}

#[cfg(feature = "hdf5")]
pub(crate) mod imp {
    use std::sync::atomic::{AtomicU64, Ordering};

    use hdf5_metno as h5;
    use hdf5_metno::types::TypeDescriptor;
    use ndarray::Array2;

    use super::{bad, Reading, FORMAT};
    use crate::topography::{Channel, Heights};
    use crate::Result;

    /// The deepest group nesting followed, and the most links visited (a file whose hard
    /// links form a cycle must still end).
    const MAX_DEPTH: usize = 32;
    const MAX_LINKS: usize = 100_000;

    /// Largest expansion of a compressed dataset over its stored bytes: deflate's limit
    /// (1032:1) with a margin.
    const MAX_EXPANSION: u64 = 1100;

    /// Gives the error of the HDF5 library as one of ours.
    pub(crate) fn lib(e: h5::Error) -> crate::Error {
        bad(FORMAT, format!("the HDF5 library refused it: {e}"))
    }

    /// Opens `bytes` as an HDF5 file held in memory (core driver, file image: the library
    /// copies the bytes and never touches the disk).
    pub(crate) fn open(bytes: &[u8]) -> Result<h5::File> {
        // Each image gets its own name: the library shares an open file by name.
        static IMAGES: AtomicU64 = AtomicU64::new(0);
        let name = format!("asperity-image-{}", IMAGES.fetch_add(1, Ordering::Relaxed));
        let name = std::ffi::CString::new(name).expect("no NUL in the name");
        h5::sync::sync(|| {
            let fapl = h5::file::FileAccess::build()
                .core_filebacked(false)
                .finish()
                .map_err(lib)?;
            // SAFETY: the property list is live; the library copies the image (no
            // callbacks are set), so `bytes` need only outlive the call.
            let rc = unsafe {
                hdf5_metno_sys::h5p::H5Pset_file_image(
                    fapl.id(),
                    bytes.as_ptr() as *mut std::ffi::c_void,
                    bytes.len(),
                )
            };
            if rc < 0 {
                return Err(bad(FORMAT, "the HDF5 library refused the file image"));
            }
            // SAFETY: a NUL-terminated name and a live property list; a negative id is
            // an error, checked before the id is wrapped.
            let id = unsafe {
                hdf5_metno_sys::h5f::H5Fopen(
                    name.as_ptr(),
                    hdf5_metno_sys::h5f::H5F_ACC_RDONLY,
                    fapl.id(),
                )
            };
            if id < 0 {
                return Err(bad(
                    FORMAT,
                    "not a readable HDF5 file (the library could not open it)",
                ));
            }
            // SAFETY: `id` is a file the library just opened; the wrapper closes it.
            unsafe { h5::from_id::<h5::File>(id) }.map_err(lib)
        })
    }

    pub(super) fn read(bytes: &[u8]) -> Result<Reading> {
        let file = open(bytes)?;
        let mut channels = Vec::new();
        let mut links = 0;
        collect(&file, "", 0, &mut links, bytes.len(), &mut channels)?;
        if channels.is_empty() {
            return Err(bad(
                FORMAT,
                "no two-dimensional numeric dataset (a map) in the file",
            ));
        }
        Ok(Reading {
            format: FORMAT,
            channels,
        })
    }

    /// The hard links of `group` in name order: datasets that are maps become channels,
    /// groups are descended into.
    fn collect(
        group: &h5::Group,
        prefix: &str,
        depth: usize,
        links: &mut usize,
        file_len: usize,
        out: &mut Vec<Channel>,
    ) -> Result<()> {
        let mut names = Vec::new();
        group
            .iter_visit(
                h5::IndexType::Name,
                h5::IterationOrder::Increasing,
                |name, info| {
                    if matches!(info.link_type, h5::LinkType::Hard) {
                        names.push(name.to_string());
                    }
                    Ok(())
                },
            )
            .map_err(lib)?;
        for name in names {
            *links += 1;
            if *links > MAX_LINKS {
                return Err(bad(FORMAT, format!("more than {MAX_LINKS} links")));
            }
            let path = if prefix.is_empty() {
                name.clone()
            } else {
                format!("{prefix}/{name}")
            };
            if let Ok(ds) = group.dataset(&name) {
                if let Some(h) = map_of(&ds, file_len)? {
                    out.push(Channel {
                        name: path,
                        heights: Heights::Areal(h),
                        size: [None, None],
                        unit: None,
                        is_height: true,
                    });
                }
            } else if let Ok(g) = group.group(&name) {
                if depth + 1 >= MAX_DEPTH {
                    return Err(bad(
                        FORMAT,
                        format!("groups nested deeper than {MAX_DEPTH}"),
                    ));
                }
                collect(&g, &path, depth + 1, links, file_len, out)?;
            }
        }
        Ok(())
    }

    /// Whether a dataset's values are numbers asperity reads (integers or floats).
    pub(crate) fn numeric(ds: &h5::Dataset) -> bool {
        ds.dtype()
            .and_then(|t| t.to_descriptor())
            .map(|d| {
                matches!(
                    d,
                    TypeDescriptor::Integer(_)
                        | TypeDescriptor::Unsigned(_)
                        | TypeDescriptor::Float(_)
                )
            })
            .unwrap_or(false)
    }

    /// A two-dimensional numeric dataset as our `(y, x)` map (its transpose), `None` for
    /// anything else; refused where it claims more values than the file can hold.
    fn map_of(ds: &h5::Dataset, file_len: usize) -> Result<Option<Array2<f64>>> {
        let shape = ds.shape();
        if shape.len() != 2 || shape.contains(&0) || !numeric(ds) {
            return Ok(None);
        }
        let values = read_values(ds, file_len)?;
        Ok(Some(
            values.reversed_axes().as_standard_layout().into_owned(),
        ))
    }

    /// The values of a two-dimensional numeric dataset as stored (`[first, second]` index),
    /// converted to f64 by the library, after the bound on what its bytes can hold.
    pub(crate) fn read_values(ds: &h5::Dataset, file_len: usize) -> Result<Array2<f64>> {
        let shape = ds.shape();
        let element = ds.dtype().map_err(lib)?.size() as u64;
        let count = shape.iter().try_fold(1u64, |a, &n| a.checked_mul(n as u64));
        let raw = count.and_then(|c| c.checked_mul(element.max(1)));
        let stored = ds.storage_size();
        let limit = if ds.filters().is_empty() {
            stored.min(file_len as u64)
        } else {
            stored.min(file_len as u64).saturating_mul(MAX_EXPANSION)
        };
        match raw {
            Some(r) if r <= limit => {}
            _ => {
                return Err(bad(
                    FORMAT,
                    format!(
                    "dataset {} claims {shape:?} values, more than its {stored} stored bytes hold",
                    ds.name()
                ),
                ))
            }
        }
        crate::memory::ensure_fits(
            &format!("reading HDF5 dataset {}", ds.name()),
            count.and_then(|c| c.checked_mul(8)),
        )?;
        ds.read_2d::<f64>().map_err(lib)
    }
}

#[cfg(all(test, feature = "hdf5"))]
mod tests {
    use super::super::testkit::{assert_robust, check_shared, Expect};
    use super::*;
    use std::time::Duration;

    #[test]
    fn multiple_data_sets_reads_like_the_reference() {
        // No size or unit in the file: the reference was given one unit per pixel, ours
        // stays without (the size is asked for when the file is read).
        let expect = Expect {
            size: Some([None, None]),
            ..Expect::default()
        };
        check_shared("topographies-3", "multiple_data_sets.h5", expect);
    }

    #[test]
    fn a_corrupt_hdf5_file_is_refused_without_a_panic() {
        let Some(dir) = super::super::testkit::set_dir("topographies-3") else {
            return;
        };
        let bytes = std::fs::read(dir.join("multiple_data_sets.h5")).unwrap();
        assert_robust(&bytes, sniff, read, 4096, Some(8), Duration::from_secs(3));
    }
}

#[cfg(all(test, not(feature = "hdf5")))]
mod tests_without_the_library {
    #[test]
    fn an_hdf5_file_names_the_missing_feature() {
        let mut bytes = super::SIGNATURE.to_vec();
        bytes.extend_from_slice(&[0u8; 120]);
        assert!(super::sniff(&bytes));
        // A whole superblock (version 0, 8-byte offsets, end of file at 0).
        bytes[13] = 8;
        let err = super::read(&bytes).unwrap_err().to_string();
        assert!(err.contains("--features hdf5"), "{err}");
    }
}
