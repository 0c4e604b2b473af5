use mote_rcp::*;
fn main() {
    for s in [0.25, 0.5, 1.0, 1.18, 1.5, 2.0, 2.5, 3.0] {
        let d = SizeDistribution::lognormal(s).unwrap();
        let a = RodPacking::default().estimate(&d).unwrap().phi;
        let c = RodPacking::default().erfc(ErfcFlavour::AbramowitzStegun).estimate(&d).unwrap().phi;
        let b = baseline::estimate(&d, 16000, 0.7654, ErfcFlavour::AbramowitzStegun);
        println!("sigma {s}: accurate {a:.6} compat {c:.6} baseline-compat {b:.6} diff {:.1e} fit {:.6}", a - c, lognormal_fit(s, false));
    }
}
