use super::*;

/// Bitwise equality of two files' contents (NaN equal to NaN, −0 not equal to +0).
fn assert_identical(a: &FieldFile, b: &FieldFile) {
    assert_eq!(a.grid, b.grid);
    assert_eq!(a.dims, b.dims);
    assert_eq!(a.attributes, b.attributes);
    assert_eq!(a.variables.len(), b.variables.len());
    for (x, y) in a.variables.iter().zip(&b.variables) {
        assert_eq!(
            (&x.name, &x.dims, &x.long_name, &x.units, &x.comment),
            (&y.name, &y.dims, &y.long_name, &y.units, &y.comment)
        );
        match (&x.values, &y.values) {
            (Values::Real(p), Values::Real(q)) => {
                let bits = |v: &[f64]| -> Vec<u64> {
                    v.iter()
                        .map(|x| if x.is_nan() { u64::MAX } else { x.to_bits() })
                        .collect()
                };
                assert_eq!(bits(p), bits(q), "{}", x.name);
            }
            (p, q) => assert_eq!(p, q, "{}", x.name),
        }
    }
}

/// A sweep's fields: 3 loads on a 5 × 7 grid with rectangular pixels, columns with a
/// missing value, a contact set, patch labels and a patch dimension.
fn sample() -> FieldFile {
    let (loads, rows, cols) = (3, 5, 7);
    let n = loads * rows * cols;
    // Awkward doubles: subnormal, −0, the extremes, irrational-looking fractions.
    let specials = [5e-324, -0.0, f64::MAX, f64::MIN_POSITIVE, 1.0 / 3.0, -1e300];
    let pressure: Vec<f64> = (0..n)
        .map(|i| {
            specials
                .get(i)
                .copied()
                .unwrap_or((i as f64).sqrt() * 1.234_567e6)
        })
        .collect();
    let gap: Vec<f64> = (0..n)
        .map(|i| (i as f64 * 0.7).sin().abs() * 1e-6)
        .collect();
    let contact: Vec<bool> = pressure.iter().map(|&p| p > 1e7).collect();
    let labels: Vec<i32> = (0..rows * cols).map(|i| (i % 4) as i32 - 1).collect();
    let var = |name: &str, dims: &[&str], units: Option<&str>, values| Variable {
        name: name.into(),
        dims: dims.iter().map(|d| d.to_string()).collect(),
        long_name: format!("the {name}"),
        units: units.map(str::to_string),
        comment: (units.is_none()).then(|| "in the units of the heights — µm".to_string()),
        values,
    };
    FieldFile {
        grid: Some(Grid {
            rows,
            cols,
            size: 7e-6,
            size_y: 2.5e-6,
            units: Some("m".into()),
        }),
        dims: vec![("load".into(), loads), ("patch".into(), 2)],
        variables: vec![
            var(
                "mean_pressure",
                &["load"],
                Some("Pa"),
                Values::Real(vec![1e5, 1e6, 1e7]),
            ),
            var(
                "stiffness_fd",
                &["load"],
                Some("N/m"),
                Values::Real(vec![f64::NAN, 2.0, f64::NAN]),
            ),
            var(
                "pressure",
                &["load", "y", "x"],
                Some("Pa"),
                Values::Real(pressure),
            ),
            var("gap", &["load", "y", "x"], None, Values::Real(gap)),
            var("contact", &["load", "y", "x"], None, Values::Flag(contact)),
            var(
                "patch_labels",
                &["y", "x"],
                Some("1"),
                Values::Integer(labels),
            ),
            var(
                "patch_areas",
                &["patch"],
                Some("m2"),
                Values::Real(vec![1e-12, 3e-12]),
            ),
        ],
        attributes: vec![
            ("title".into(), "contact fields".into()),
            (
                "asperity_record".into(),
                "{\"kind\": \"sweep\", \"Δγ\": 0.5}".into(),
            ),
        ],
    }
}

#[test]
fn write_then_read_gives_back_every_bit() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sweep.nc");
    let file = sample();
    file.write(&path, false).unwrap();
    let back = FieldFile::read(&path).unwrap();
    assert_identical(&file, &back);
    // Written again, the bytes are the same: nothing depends on the run.
    assert_eq!(back.to_bytes().unwrap(), std::fs::read(&path).unwrap());
    // The classic format, with the column's NaN stored as the CF fill value.
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..4], b"CDF\x01");
    let fill = FILL.to_be_bytes();
    assert!(bytes.windows(8).any(|w| w == fill));
}

#[test]
fn the_topography_reader_reads_a_map_with_its_sizes() {
    // One NetCDF reader serves both: a gap map in metres reads as a height channel.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gap.nc");
    let mut file = sample();
    file.variables
        .retain(|v| v.name == "gap" || v.name == "patch_labels");
    file.dims.clear();
    let gap: Vec<f64> = (0..35).map(|i| i as f64 * 1e-7).collect();
    file.variables[0].dims = vec!["y".into(), "x".into()];
    file.variables[0].units = Some("m".into());
    file.variables[0].values = Values::Real(gap.clone());
    file.write(&path, false).unwrap();
    let t = crate::topography::read_file(&path, &Default::default()).unwrap();
    assert_eq!(t.sizes, vec![7e-6, 2.5e-6]);
    let crate::topography::Heights::Areal(h) = &t.heights else {
        panic!("a map")
    };
    assert_eq!(h.dim(), (5, 7));
    assert_eq!(h.iter().copied().collect::<Vec<_>>(), gap);
}

#[test]
fn bad_contents_are_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.nc");
    let refuse = |file: FieldFile, words: &str| {
        let e = file.write(&path, false).unwrap_err().to_string();
        assert!(e.contains(words), "{e}");
        assert!(!e.contains('\n'), "{e}");
        assert!(!path.exists());
    };
    let mut f = sample();
    if let Values::Real(p) = &mut f.variables[2].values {
        p[3] = f64::NAN; // a map holds no NaN
    }
    refuse(f, "non-finite");
    let mut f = sample();
    f.variables[0].values = Values::Real(vec![1.0, f64::INFINITY, 2.0]);
    refuse(f, "non-finite");
    let mut f = sample();
    f.variables[1].values = Values::Real(vec![f64::NAN, FILL, 1.0]); // would read back NaN
    refuse(f, "non-finite");
    let mut f = sample();
    f.variables[0].values = Values::Real(vec![1.0]);
    refuse(f, "1 values for dimensions");
    let mut f = sample();
    f.variables[0].dims = vec!["time".into()];
    refuse(f, "no dimension time");
    let mut f = sample();
    f.variables[1].name = "x".into();
    refuse(f, "x is named twice");
    let mut f = sample();
    f.variables[1].name = "a/b".into(); // no slash in a NetCDF name
    refuse(f, "not a valid NetCDF name");
    let mut f = sample();
    f.dims[1].1 = 0;
    refuse(f, "length 0");
    let mut f = sample();
    f.grid.as_mut().unwrap().size = -1.0;
    refuse(f, "positive and finite");
    let mut f = sample();
    f.attributes.push(("Conventions".into(), "mine".into()));
    refuse(f, "cannot be written");
}

#[test]
fn an_existing_file_is_kept_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("kept.nc");
    std::fs::write(&path, b"mine").unwrap();
    assert!(sample().write(&path, false).is_err());
    assert_eq!(std::fs::read(&path).unwrap(), b"mine");
    sample().write(&path, true).unwrap();
    assert_identical(&FieldFile::read(&path).unwrap(), &sample());
}

#[test]
fn damaged_files_are_refused_without_panicking() {
    let bytes = sample().to_bytes().unwrap();
    for cut in [0, 3, 4, 17, 100, bytes.len() / 2, bytes.len() - 1] {
        assert!(
            FieldFile::from_bytes(&bytes[..cut]).is_err(),
            "cut at {cut}"
        );
    }
    for k in (0..bytes.len().min(2000)).step_by(7) {
        let mut b = bytes.clone();
        b[k] ^= 0xA5;
        let _ = FieldFile::from_bytes(&b); // an error or another file, never a panic
    }
    // A NetCDF file of another kind (no Conventions): refused by name.
    let mut other = sample();
    other.attributes.clear();
    let mut b = other.to_bytes().unwrap();
    let at = b.windows(11).position(|w| w == b"Conventions").unwrap();
    b[at] = b'K';
    let e = FieldFile::from_bytes(&b).unwrap_err().to_string();
    assert!(e.contains("not a field file"), "{e}");
}

#[test]
fn netcdf_paths_are_known_by_their_extension() {
    assert!(is_netcdf_path(Path::new("a/fields.nc")));
    assert!(is_netcdf_path(Path::new("FIELDS.NC")));
    assert!(!is_netcdf_path(Path::new("fields")));
    assert!(!is_netcdf_path(Path::new("fields.nc4")));
}
