//! Packing benchmark and diagnostics: `pack_bench D N RATE SEED [PMAX] [RESCALE]`
//! `[RESCALE] [jam]`: prints φ_J, Z, collisions and contact statistics at several tolerances.
use mote_edmd::analyse::{bond_order, contacts, deepest_overlap};
use mote_edmd::pack::{Finish, PackSettings, Packer};

fn run<const D: usize>(n: usize, rate: f64, seed: u64, pmax: f64, rescale: f64, jam: bool) {
    let settings = PackSettings {
        n,
        rate,
        seed,
        max_pressure: pmax,
        rescale_every: rescale,
        finish: jam.then(Finish::default),
        ..PackSettings::default()
    };
    let t0 = std::time::Instant::now();
    let mut p = Packer::<D>::new(settings).expect("valid settings");
    let out = p.run(|_| {}).expect("run");
    let secs = t0.elapsed().as_secs_f64();
    let sys = p.system();
    let (b, pos, radii) = (*sys.simbox(), sys.positions(), sys.radii());
    println!(
        "D={D} N={n} rate={rate} seed={seed} phi={:.5} Z={:.3e} coll={} epochs={} stop={} wall={secs:.2}s",
        out.phi,
        out.pressure,
        out.collisions,
        out.epochs,
        out.stop.name()
    );
    for tol in [1e-12, 1e-10, 1e-9, 1e-8, 1e-6, 1e-4] {
        let c = contacts(&b, &pos, &radii, tol);
        let zall = c.z.iter().sum::<usize>() as f64 / n as f64;
        println!(
            "  tol {tol:e}: z_all {zall:.4} rattlers {} backbone z {:.4}",
            c.rattlers(),
            c.backbone_z
        );
    }
    let mut relax = mote_edmd::System::new(
        b,
        pos.clone(),
        sys.velocities(),
        radii.clone(),
        sys.masses(),
    )
    .expect("relax");
    for w in 0..4 {
        relax.reset_counters();
        relax.run_collisions(10 * n as u64);
        println!("  relax window {w}: Z = {:.3e}", relax.compressibility());
    }
    println!(
        "  order {:.4} overlap {:?}",
        bond_order(&b, &pos, &radii, 1.2).0,
        deepest_overlap(&b, &pos, &radii)
    );
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let get = |k: usize, d: &str| a.get(k).cloned().unwrap_or_else(|| d.to_string());
    let dim: usize = get(1, "3").parse().expect("D");
    let n: usize = get(2, "1000").parse().expect("N");
    let rate: f64 = get(3, "0.01").parse().expect("rate");
    let seed: u64 = get(4, "1").parse().expect("seed");
    let pmax: f64 = get(5, "1e12").parse().expect("pmax");
    let rescale: f64 = get(6, "10").parse().expect("rescale");
    let jam = get(7, "") == "jam";
    if dim == 2 {
        run::<2>(n, rate, seed, pmax, rescale, jam)
    } else {
        run::<3>(n, rate, seed, pmax, rescale, jam)
    }
}
