//! Tests of the BEM as a whole, beside its code: the recorded bits of a set of solves
//! ([`fingerprint`]) and the solver on rectangular pixels against Hertz and finite
//! differences ([`rectangular_pixels`]). The tests of one part sit at the bottom of its file;
//! the allocation counts stay in `crates/asperity/tests/` (they need the process's global
//! allocator).

mod fingerprint;
mod rectangular_pixels;
