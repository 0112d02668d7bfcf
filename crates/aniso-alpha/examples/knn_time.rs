//! Times the kd-tree's 16-nearest queries of every point of a file, in
//! tree order (as the local analysis makes them), and prints the build
//! time and the time a query (the fastest of five passes).
//!
//! `cargo run --release --example knn_time -- scan.ply`
use aniso_alpha::geometry::kdtree::KdTree;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: knn_time FILE")?;
    let cloud = aniso_alpha::io::read_points(std::path::Path::new(&path), &Default::default())?;
    let pts = cloud.points;
    let t0 = Instant::now();
    let tree = KdTree::new(&pts, None);
    let build = t0.elapsed().as_secs_f64();
    let mut out = Vec::new();
    // A sum of the neighbours' indices: the same for any layout or leaf
    // size (ties are broken by index), and it keeps the queries alive.
    let mut check = 0u64;
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t1 = Instant::now();
        check = 0;
        for &i in tree.order() {
            tree.nearest(&pts[i as usize], 16, &mut out);
            check = check.wrapping_add(out.iter().map(|x| u64::from(x.1)).sum::<u64>());
        }
        best = best.min(t1.elapsed().as_secs_f64());
    }
    println!(
        "points {} build {:.4} s query {:.3} us check {}",
        pts.len(),
        build,
        best / pts.len().max(1) as f64 * 1e6,
        check
    );
    Ok(())
}
