//! The adhesive BEM iteration allocates nothing per round or CG iteration: moving a warm
//! [`PixelAdhesion`] costs the same number of heap allocations whether the move takes few
//! or many rounds and iterations. (Its own binary, with a counting allocator, as
//! `bem_allocation.rs`; one test, so that nothing else allocates while it counts.)

use asperity::bem::adhesion::PixelAdhesion;
use asperity::bem::HalfSpace;
use asperity::surface::Surface;
use ndarray::Array2;

mod common;
use common::count;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

#[test]
fn moves_allocate_nothing_per_round_or_iteration() {
    // One rayon thread, as in bem_allocation.rs: the count is then the iteration's own.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    pool.install(|| {
        // A positive control: the counter sees this thread's allocations.
        let (_, allocations, _) = count(|| std::hint::black_box(Vec::<u8>::with_capacity(24)));
        assert_eq!(allocations, 1);
        let (n, dx) = (48, 5e-3);
        let heights = Array2::from_shape_fn((n, n), |(i, j)| {
            let (y, x) = ((i as f64 - 24.0) * dx, (j as f64 - 24.0) * dx);
            -(x * x + y * y) / 2.0
        });
        let surface = Surface::new(heights, n as f64 * dx).unwrap();
        let mut contact = PixelAdhesion::new(&surface, HalfSpace::default(), 2e-4).unwrap();
        contact.move_to(0.002).unwrap();
        let mut counted = Vec::new();
        // A small step (few rounds), a long one (many), a retraction that releases pixels.
        for d in [0.0021, 0.009, 0.002] {
            let ((_, info), allocations, _) = count(|| contact.move_to(d).unwrap());
            counted.push((allocations, info.rounds, info.cg_iterations));
        }
        let (first, _, _) = counted[0];
        assert!(
            counted.iter().all(|&(a, _, _)| a == first),
            "allocations depend on the work: {counted:?}"
        );
        let spread = |f: fn(&(u64, usize, usize)) -> usize| {
            counted.iter().map(f).max().unwrap() > counted.iter().map(f).min().unwrap()
        };
        assert!(spread(|c| c.1) && spread(|c| c.2), "{counted:?}");
        assert!(first <= 16, "{counted:?}");
    });
}
