//! Times the kd-tree's nearest queries of every point of a file, in tree
//! order (as the local analysis makes them): its 16 nearest points, and
//! its nearest point among one in four (a subsample's tree), each one by
//! one (`KdTree::nearest`) and a leaf at a time (`LeafBatch`). Prints the
//! build time and the time a query of each (the fastest of five passes),
//! and whether the two ways gave the same lists.
//!
//! `cargo run --release --example knn_time -- scan.ply`
use aniso_alpha::geometry::kdtree::KdTree;
use std::time::Instant;

/// A sum of the neighbours' indices and distances: the same for any
/// layout or leaf size (ties are broken by index), and it keeps the
/// queries alive.
fn sum(out: &[(f64, u32)]) -> u64 {
    out.iter()
        .map(|x| u64::from(x.1) ^ x.0.to_bits())
        .fold(0, u64::wrapping_add)
}

/// The best time of five passes of `pass` (which returns its check sum)
/// per point, and the check sum.
fn time(n: usize, mut pass: impl FnMut() -> u64) -> (f64, u64) {
    let mut best = f64::INFINITY;
    let mut check = 0;
    for _ in 0..5 {
        let t = Instant::now();
        check = pass();
        best = best.min(t.elapsed().as_secs_f64());
    }
    (best / n.max(1) as f64 * 1e6, check)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: knn_time FILE")?;
    let cloud = aniso_alpha::io::read_points(std::path::Path::new(&path), &Default::default())?;
    let pts = cloud.points;
    let t0 = Instant::now();
    let tree = KdTree::new(&pts, None);
    let build = t0.elapsed().as_secs_f64();
    let quarter = KdTree::new(&pts, Some((0..pts.len() as u32).step_by(4).collect()));
    let n = pts.len();
    let mut out = Vec::new();
    for (name, to, k) in [("16 nearest", &tree, 16), ("1 nearest of 1/4", &quarter, 1)] {
        let (one, check) = time(n, || {
            let mut c = 0u64;
            for &i in tree.order() {
                to.nearest(&pts[i as usize], k, &mut out);
                c = c.wrapping_add(sum(&out));
            }
            c
        });
        let (batched, batch_check) = time(n, || {
            let mut c = 0u64;
            let mut batch = to.batch(&tree);
            for t in 0..n {
                batch.nearest(t, k, &mut out);
                c = c.wrapping_add(sum(&out));
            }
            c
        });
        println!(
            "{name}: one by one {one:.3} us, by leaf {batched:.3} us a query ({})",
            if check == batch_check {
                "same"
            } else {
                "DIFFERENT"
            }
        );
    }
    println!("points {n} build {build:.4} s");
    Ok(())
}
