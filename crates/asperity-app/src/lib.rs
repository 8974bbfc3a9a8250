//! The front-end layer of asperity: the requests that both front ends (the `asperity` CLI
//! and the Python package) build from their arguments, validate here once and run here.
//!
//! A front end does conversions only: flags or keywords → a request → [`validate`] → run →
//! write (CSV, JSON) or hand back (numpy). Every rule on a user's input, every default and
//! every result column lives here once, so the two front ends refuse the same requests in
//! the same words ([`Refusal::words`] names a parameter as a flag, `--tol`, or as a
//! keyword, `tolerance`) and give the same numbers.
//!
//! [`validate`]: bem::BemRequest::validate
//!
//! ```
//! use asperity_app::bem::{BemRequest, Loads, SolverRequest};
//! use asperity_app::refusal::Names;
//!
//! let request = BemRequest {
//!     loads: Loads::Pressures(vec![0.01, 0.05]),
//!     solver: SolverRequest {
//!         tolerance: 0.5, // a relative residual of 50 %: meaningless
//!         ..SolverRequest::default()
//!     },
//!     ..BemRequest::default()
//! };
//! let refusal = request.validate().unwrap_err();
//! assert!(refusal.words(Names::Flags).starts_with("--tol must be positive and at most"));
//! assert!(refusal.words(Names::Keywords).starts_with("tolerance must be positive"));
//! ```

pub mod adhesion;
pub mod argument;
pub mod bem;
pub mod contact;
pub mod contact_adhesion;
pub mod derived;
pub mod fields;
pub mod figure;
pub mod import;
pub mod mdr;
pub mod measured;
pub mod persson;
pub mod range;
pub mod refusal;
pub mod slip;
pub mod stats;
pub mod study;
pub mod surface;
pub mod table;

pub use refusal::{Names, Param, Refusal, RequestError};
