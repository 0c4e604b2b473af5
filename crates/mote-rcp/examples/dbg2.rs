use mote_rcp::*;
use std::time::Instant;
fn main() {
    let ln = SizeDistribution::new([Population::lognormal_d32(2.0, 0.5, 1.0).unwrap()]).unwrap();
    let t = Instant::now();
    let mut s = 0.0;
    for i in 0..10_000_000 { s += ln.cdf_point(0.01 + i as f64 * 3e-7, ErfcFlavour::Accurate).cdf; }
    println!("cdf_point {:?} {s}", t.elapsed());
    let t = Instant::now();
    let mut s = 0.0;
    for i in 0..10_000_000 { s += libm::erfc(-3.0 + i as f64 * 6e-7); }
    println!("erfc {:?} {s}", t.elapsed());
    let t = Instant::now();
    let mut s = 0.0;
    for i in 0..10_000_000 { s += (0.01 + i as f64 * 3e-7f64).ln(); }
    println!("ln {:?} {s}", t.elapsed());
}
