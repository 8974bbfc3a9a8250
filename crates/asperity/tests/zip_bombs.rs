//! Zip bombs in the zip-based topography formats (Keyence ZON, VK6, VK7; X3P; Mitutoyo
//! `.xlsx`), read through the public [`asperity::topography::read_file`]: a member that
//! declares 4 GiB from a few hundred compressed bytes, and one that declares 1000 bytes but
//! inflates to 64 MiB, are refused in one line, and no single allocation made while reading
//! them comes near either size.
//!
//! The counting global allocator of `tests/common` (it records the largest allocation made
//! on the reading thread) applies to this test binary only; this binary holds one test so
//! that no other test allocates while it measures.

use std::io::Write;

use asperity::topography::{read_file, ReadOptions};

mod common;
use common::largest_allocation;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

/// `prefix` then a zip archive whose one member `name` holds `data`, deflated.
fn container(prefix: &[u8], name: &str, data: &[u8]) -> Vec<u8> {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    zip.start_file(name, options).unwrap();
    zip.write_all(data).unwrap();
    let mut file = prefix.to_vec();
    file.extend_from_slice(&zip.finish().unwrap().into_inner());
    file
}

/// Sets the uncompressed size of every member, in its local and central headers.
fn declare_size(zip: &mut [u8], size: u32) {
    for i in 0..zip.len().saturating_sub(30) {
        if zip[i..].starts_with(b"PK\x03\x04") {
            zip[i + 22..i + 26].copy_from_slice(&size.to_le_bytes());
        } else if zip[i..].starts_with(b"PK\x01\x02") {
            zip[i + 24..i + 28].copy_from_slice(&size.to_le_bytes());
        }
    }
}

/// A VK4 file whose one height image (offset table entry 6) declares `w × h` 32-bit
/// samples, followed by `filler` bytes: the format's own layout (header, offset table, 304
/// bytes of measurement conditions, image header and palette).
fn forged_vk4(w: u32, h: u32, filler: usize) -> Vec<u8> {
    let mut f = b"VK4_\x01\x00\x00\x00\0\0\0\0".to_vec();
    let image_at = 12 + 72 + 304;
    let mut table = [0u32; 18];
    table[6] = image_at;
    f.extend(table.iter().flat_map(|v| v.to_le_bytes()));
    let mut conditions = vec![0u32; 76];
    conditions[0] = 304;
    (conditions[42], conditions[43], conditions[44]) = (1_000, 1_000, 1_000);
    f.extend(conditions.iter().flat_map(|v| v.to_le_bytes()));
    let bytes = u64::from(w) * u64::from(h) * 4;
    for v in [w, h, 32, 0, bytes as u32, 0, 0] {
        f.extend_from_slice(&v.to_le_bytes());
    }
    f.extend_from_slice(&[0u8; 768]);
    f.resize(f.len() + filler, 0);
    f
}

#[test]
fn zip_bombs_are_refused_in_one_line_without_allocating_them() {
    forged_vk4_headers_are_refused_before_the_member_is_inflated();
    // (file name, bytes before the archive, the member the reader opens first)
    let mut zon_prefix = b"KPK0".to_vec();
    zon_prefix.extend_from_slice(&2u32.to_le_bytes());
    zon_prefix.extend_from_slice(b"BM");
    let formats: [(&str, Vec<u8>, &str); 5] = [
        (
            "bomb.zon",
            zon_prefix,
            "686613b8-27b5-4a29-8ffc-438c2780873e",
        ),
        ("bomb.vk6", b"VK6\0\0\0\0\0\0\0\0\0".to_vec(), "Vk4File"),
        ("bomb.vk7", b"VK7\0\0\0\0\0\0\0\0\0".to_vec(), "Vk4File"),
        ("bomb.x3p", Vec::new(), "main.xml"),
        ("bomb.xlsx", Vec::new(), "xl/workbook.xml"),
    ];
    let dir = tempfile::tempdir().unwrap();
    let zeros = vec![0u8; 64 << 20];
    for (file, prefix, member) in formats {
        let path = dir.path().join(file);
        // Declares 4 GiB − 2 from a few hundred bytes; then declares 1000 bytes and
        // inflates to 64 MiB (about 64 KiB deflated).
        let mut declared = container(&prefix, member, &[7u8; 4096]);
        declare_size(&mut declared, u32::MAX - 1);
        let mut lying = container(&prefix, member, &zeros);
        declare_size(&mut lying, 1000);
        for (what, bytes) in [("declared", declared), ("lying", lying)] {
            std::fs::write(&path, &bytes).unwrap();
            let (err, largest) = largest_allocation(|| read_file(&path, &ReadOptions::default()));
            let err = err.expect_err(file).to_string();
            assert_eq!(err.lines().count(), 1, "{file} ({what}): {err}");
            // The file itself is read whole: allow it, and 1 MiB of working buffers.
            assert!(
                largest <= bytes.len() + (1 << 20),
                "{file} ({what}): an allocation of {largest} bytes for a file of {}",
                bytes.len()
            );
            eprintln!(
                "{file} ({what}, {} bytes): {err}; largest allocation {largest} bytes",
                bytes.len()
            );
        }
    }
}

/// A VK6/VK7 whose `Vk4File` is honest about its size (32 MiB of zeros, deflated to about
/// 32 KiB: within the ratio a deflated member may have) but whose VK4 header declares a
/// 20000 × 20000 × 32-bit height image (1.6 GB): refused from the header, in one line,
/// before the member is inflated (no allocation near its 32 MiB).
fn forged_vk4_headers_are_refused_before_the_member_is_inflated() {
    let dir = tempfile::tempdir().unwrap();
    let member = forged_vk4(20_000, 20_000, 32 << 20);
    for magic in [&b"VK6"[..], b"VK7"] {
        let mut prefix = magic.to_vec();
        prefix.resize(24, 0);
        let bytes = container(&prefix, "Vk4File", &member);
        // Not refused for its ratio: the header is what refuses it.
        assert!((bytes.len() as u64) * 1100 > member.len() as u64);
        let path = dir.path().join("forged.vk6");
        std::fs::write(&path, &bytes).unwrap();
        let (err, largest) = largest_allocation(|| read_file(&path, &ReadOptions::default()));
        let err = err.expect_err("forged").to_string();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains("20000 × 20000 × 32 bits"), "{err}");
        assert!(
            largest <= bytes.len() + (1 << 20),
            "an allocation of {largest} bytes for a file of {}",
            bytes.len()
        );
        eprintln!(
            "forged VK4 header ({} bytes): {err}; largest allocation {largest} bytes",
            bytes.len()
        );
    }
}
