//! Studies: the rules on a study's request that the library's own validation does not
//! make, checked by both front ends before a study runs.

use asperity::study::{Method, StudySpec};

use crate::refusal::{Param, Refusal};

/// The smallest number of contacts of the α fit window.
pub const MIN_CONTACTS: Param = Param::new("--min-contacts", "min_contacts");

/// Refuses a fit window that starts above the number of points of the smallest sample (N
/// springs on an MDR line, N×N on a BEM surface): no load could reach it, and every α of
/// that size would be empty.
pub fn check_min_contacts(spec: &StudySpec) -> Result<(), Refusal> {
    let Some(&n) = spec.sizes.iter().min() else {
        return Ok(());
    };
    let (points, grid) = match spec.method {
        Method::Mdr => (n, format!("a line of {n} springs")),
        Method::Bem => (n.saturating_mul(n), format!("a {n}x{n} surface")),
    };
    let min_contacts = spec.window.min_contacts;
    if min_contacts <= points {
        return Ok(());
    }
    Err(Refusal::of(MIN_CONTACTS).text(format!(
        " {min_contacts} is above the number of points of the smallest sample ({grid} has \
         {points}): no load reaches it"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use asperity::study::FitWindow;

    #[test]
    fn the_window_must_fit_the_grid() {
        let spec = |method, min_contacts| StudySpec {
            method,
            sizes: vec![64, 32],
            hursts: vec![0.5],
            samples: 1,
            rolloff: None,
            seed: 1,
            window: FitWindow {
                min_contacts,
                max_fraction: 0.1,
            },
            levels: 48,
            sweep_end: None,
        };
        assert!(check_min_contacts(&spec(Method::Mdr, 32)).is_ok());
        assert!(check_min_contacts(&spec(Method::Bem, 1024)).is_ok());
        let err = check_min_contacts(&spec(Method::Mdr, 33)).unwrap_err();
        assert_eq!(
            err.to_string(),
            "--min-contacts 33 is above the number of points of the smallest sample (a line of \
             32 springs has 32): no load reaches it"
        );
        assert!(check_min_contacts(&spec(Method::Bem, 1025)).is_err());
    }
}
