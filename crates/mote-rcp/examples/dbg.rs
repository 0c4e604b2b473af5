use mote_rcp::*;
use std::time::Instant;
fn main() {
    let ln = SizeDistribution::new([Population::lognormal_d32(2.0, 0.5, 1.0).unwrap()]).unwrap();
    let ln3 = SizeDistribution::new([Population::lognormal(1.0, 0.3, 1.0), Population::lognormal(3.0, 0.5, 1.0), Population::lognormal(10.0, 0.8, 1.0)]).unwrap();
    let wide = SizeDistribution::lognormal(3.0).unwrap();
    for (name, d) in [("ln", &ln), ("ln3", &ln3), ("wide", &wide)] {
        for n in [16000usize, 100000, 10_000_000] {
            let t = Instant::now();
            let rods = d.rod_lengths(n, ErfcFlavour::Accurate).unwrap();
            let t1 = t.elapsed();
            let p = pack_rods(&rods, 0.7654).unwrap();
            let t2 = t.elapsed();
            // check accuracy vs cdf
            let nf = n as f64;
            let mut worst: f64 = 0.0;
            for i in (0..n).step_by((n / 20000).max(1)) {
                let y = (2.0 * nf - 2.0 * (i + 1) as f64 + 1.0) / (2.0 * nf);
                let pt = d.cdf_point(rods[i], ErfcFlavour::Accurate);
                worst = worst.max(((pt.cdf - y) / pt.density / rods[i]).abs());
            }
            println!("{name} {n} rods {:?} pack {:?} phi {:.9} worst rel rod err {:.1e}", t1, t2 - t1, p.phi, worst);
        }
    }
}
