//! `asperity reproduce --setting`: the medium setting's code path on tiny grids (the hidden
//! `test` setting): the folder's contents, the recorded setting, command and version, and a
//! run killed partway then resumed with the same command equals an uninterrupted one.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::run_asperity as asperity;

/// Every result file under `dir` (bookkeeping left out: stamps, timings, locks, temp files).
fn results(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    common::files_under(dir, |name| {
        name == "reproduce.json" || name == "timings.json" || name.starts_with('.')
    })
}

#[test]
fn the_test_setting_writes_a_complete_recorded_folder_and_resumes_identically() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    let run = |out: &Path| {
        vec![
            "reproduce".to_string(),
            "fig1".into(),
            "--setting".into(),
            "test".into(),
            "--out".into(),
            out.to_string_lossy().into_owned(),
        ]
    };
    let args_a = run(&a);
    let start = Instant::now();
    let o = asperity(&args_a.iter().map(String::as_str).collect::<Vec<_>>());
    let full = start.elapsed();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("fig1 (test setting): BEM on N = [16, 32], 3 samples"),
        "{stderr}"
    );
    let fig = a.join("fig1");
    for file in [
        "alpha.csv",
        "alpha.png",
        "alpha.svg",
        "report.md",
        "timings.json",
    ] {
        assert!(fig.join(file).is_file(), "{file} missing");
    }
    let read = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(fig.join(name)).unwrap()).unwrap()
    };
    let (stamp, record) = (read("reproduce.json"), read("timings.json"));
    assert_eq!(stamp["setting"], "test");
    assert_eq!(stamp["complete"], true);
    assert_eq!(record["setting"], "test");
    assert_eq!(record["version"], env!("CARGO_PKG_VERSION"));
    assert!(record["seconds"].as_f64().unwrap() > 0.0);
    let command = record["command"].as_str().unwrap();
    assert!(command.ends_with(&args_a.join(" ")), "{command}");
    let report = std::fs::read_to_string(fig.join("report.md")).unwrap();
    assert!(report.contains("**Setting: test**"), "{report}");
    // The same folder under another setting is refused, naming the one that made it.
    let o = asperity(&["reproduce", "fig1", "--quick", "--out", a.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--setting quick"));

    // Killed at half its run time, then resumed by the same command.
    let args_b = run(&b);
    let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(&args_b)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(full / 2);
    child.kill().unwrap(); // SIGKILL: no handler runs
    child.wait().unwrap();
    let o = asperity(&args_b.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(results(&a), results(&b));
    assert!(
        full < Duration::from_secs(120),
        "the test setting took {full:?}"
    );
}
