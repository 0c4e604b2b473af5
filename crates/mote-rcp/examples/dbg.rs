use mote_rcp::*;
use std::time::Instant;
fn main() {
    let ln = SizeDistribution::new([Population::lognormal_d32(2.0, 0.5, 1.0).unwrap()]).unwrap();
    let tri = SizeDistribution::new([Population::monodisperse(2.0, 1.5), Population::monodisperse(3.0, 2.5), Population::monodisperse(4.0, 3.5)]).unwrap();
    let ln3 = SizeDistribution::new([Population::lognormal(1.0, 0.3, 1.0), Population::lognormal(3.0, 0.5, 1.0), Population::lognormal(10.0, 0.8, 1.0)]).unwrap();
    for (name, d) in [("ln", &ln), ("tri", &tri), ("ln3", &ln3)] {
        for n in [100000usize, 10_000_000] {
            let t = Instant::now();
            let rods = d.rod_lengths(n, ErfcFlavour::Accurate).unwrap();
            let t1 = t.elapsed();
            let p = pack_rods(&rods, 0.7654).unwrap();
            let t2 = t.elapsed();
            println!("{name} {n} rods {:?} pack {:?} phi {:.7}", t1, t2 - t1, p.phi);
        }
    }
}
