//! What a printer engineer reads off a toning nip (seed 000): the toner
//! developed onto the belt, on the image and on the background, the
//! carrier brush and the free volume, written to nip.csv.
//!
//! - **Developed toner**: toner bodies whose centre is within 10 % of
//!   their radius of the belt's surface z_b (touching it). Each is on the
//!   image when its x in the belt's frame, x − vt (mod L), lies in a patch.
//!   Mass per area M/A = Σ m/A_region (kg/m²; 1 kg/m² = 100 mg/cm²) and
//!   charge per area q/A on the image and the background; `neutralised` is
//!   −(q/A on the image)/(σ_patch − σ_background), the fraction of the
//!   image's contrast the toner has cancelled (the space-charge limit of
//!   development is 1).
//! - **Brush**: carriers touching (sphere gaps below 2 % of the radii sum,
//!   minimum image along x and y) form clusters; `chains` counts them,
//!   `bridges` those touching both the shell and the belt (within one
//!   carrier sphere radius), `brush_height` is the mean reach of the
//!   clusters that touch the shell, z_s − (lowest sphere bottom).
//! - **Free volume**: 1 − (volume of all bodies)/(L_x L_y (z_s − z_b)).

use std::path::Path;

use glam::DVec3;
use mote_io::csv::CsvWriter;
use mote_io::Provenance;
use mote_run::Observer;

use mote_md::boundary::Boundary;
use mote_md::neighbor::VerletList;
use mote_md::rigid::run::{RigidDynamics, RigidSample};
use mote_md::rigid::{RigidBodies, WorldFrame};
use mote_md::MdError;

/// The nip's geometry and the templates it tells apart.
#[derive(Clone, Debug, PartialEq)]
pub struct NipProbe {
    pub toner: u32,
    pub carrier: u32,
    /// The belt's surface z_b and the shell's z_s.
    pub belt: f64,
    pub shell: f64,
    /// The box's x and y extent.
    pub lo: DVec3,
    pub hi: DVec3,
    /// Image patches [start, end) at t = 0, moving at `speed` along x.
    pub patches: Vec<[f64; 2]>,
    pub speed: f64,
    /// The latent image's contrast σ_patch − σ_background (0: none).
    pub contrast: f64,
    /// Where along x the developed toner and the free volume are
    /// measured, [x₀, x₁) (`None`: the whole box): a flowing nip's exit,
    /// where the developer has passed the whole development zone.
    pub window: Option<[f64; 2]>,
}

/// One measurement.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct NipSample {
    pub developed: usize,
    pub mass_image: f64,
    pub mass_background: f64,
    pub charge_image: f64,
    pub charge_background: f64,
    pub neutralised: f64,
    pub chains: usize,
    pub bridges: usize,
    pub brush_height: f64,
    pub free_volume: f64,
}

impl NipSample {
    pub const COLUMNS: [&'static str; 11] = [
        "time",
        "developed",
        "mass_per_area_image",
        "mass_per_area_background",
        "charge_per_area_image",
        "charge_per_area_background",
        "neutralised",
        "chains",
        "bridges",
        "brush_height",
        "free_volume",
    ];
}

impl NipProbe {
    fn period(&self) -> [f64; 2] {
        [self.hi.x - self.lo.x, self.hi.y - self.lo.y]
    }

    /// The image's share of the belt, by length along x.
    fn image_fraction(&self) -> f64 {
        let l = self.period()[0];
        self.patches.iter().map(|p| p[1] - p[0]).sum::<f64>() / l
    }

    fn on_image(&self, x: f64, t: f64) -> bool {
        let l = self.period()[0];
        self.patches.iter().any(|p| {
            let u = (x - self.speed * t - p[0]).rem_euclid(l);
            u < p[1] - p[0]
        })
    }

    /// The length of the image within the window [x₀, x₁) at time t,
    /// each patch's copies one period either side counted.
    fn image_in(&self, [x0, x1]: [f64; 2], t: f64) -> f64 {
        let l = self.period()[0];
        let mut inside = 0.0;
        for p in &self.patches {
            let start = self.lo.x + (p[0] + self.speed * t - self.lo.x).rem_euclid(l);
            for k in -1..=1 {
                let a = start + k as f64 * l;
                let b = a + (p[1] - p[0]);
                inside += (b.min(x1) - a.max(x0)).max(0.0);
            }
        }
        inside
    }

    /// Whether x (wrapped into the box) lies in the measuring window.
    fn in_window(&self, x: f64) -> bool {
        let l = self.period()[0];
        let x = self.lo.x + (x - self.lo.x).rem_euclid(l);
        self.window.is_none_or(|[x0, x1]| x >= x0 && x < x1)
    }

    pub fn measure(&self, b: &RigidBodies) -> NipSample {
        let mut s = NipSample::default();
        let [lx, ly] = self.period();
        let (area, a_image) = match self.window {
            Some(w) => ((w[1] - w[0]) * ly, self.image_in(w, b.time) * ly),
            None => (lx * ly, lx * ly * self.image_fraction()),
        };
        let a_background = area - a_image;
        let mut solids = 0.0;
        for i in 0..b.len() {
            let t = b.template(i);
            if !self.in_window(b.position[i].x) {
                continue;
            }
            solids += t.props.volume;
            if b.kind[i] != self.toner {
                continue;
            }
            let r = t.radii[0];
            if b.position[i].z - self.belt < 1.1 * r {
                s.developed += 1;
                if self.on_image(b.position[i].x, b.time) {
                    s.mass_image += t.props.mass;
                    s.charge_image += t.charge;
                } else {
                    s.mass_background += t.props.mass;
                    s.charge_background += t.charge;
                }
            }
        }
        let per = |x: f64, a: f64| if a > 0.0 { x / a } else { 0.0 };
        s.mass_image = per(s.mass_image, a_image);
        s.mass_background = per(s.mass_background, a_background);
        s.charge_image = per(s.charge_image, a_image);
        s.charge_background = per(s.charge_background, a_background);
        if self.contrast != 0.0 {
            s.neutralised = -s.charge_image / self.contrast;
        }
        s.free_volume = 1.0 - solids / (area * (self.shell - self.belt));
        self.brush(b, &mut s);
        s
    }

    /// Clusters of touching carriers (union–find over their spheres).
    fn brush(&self, b: &RigidBodies, s: &mut NipSample) {
        let mut world = WorldFrame::default();
        world.update(b);
        let carriers: Vec<usize> = (0..b.len())
            .filter(|&i| b.kind[i] == self.carrier)
            .collect();
        let spheres: Vec<(usize, DVec3, f64)> = carriers
            .iter()
            .enumerate()
            .flat_map(|(k, &i)| {
                let range = world.sphere_start[i] as usize..world.sphere_start[i + 1] as usize;
                range.map(move |j| (k, j))
            })
            .map(|(k, j)| (k, world.sphere_centre[j], world.sphere_radius[j]))
            .collect();
        let mut parent: Vec<usize> = (0..carriers.len()).collect();
        fn root(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        let [lx, ly] = self.period();
        // The sphere pairs within reach of touching, each once and in
        // increasing order (a half list; no pair within one carrier), then
        // those that touch joined in that order: the pairs of the loop over
        // all pairs, without its N² cost.
        let r_max = spheres.iter().fold(0.0f64, |r, s| r.max(s.2));
        if spheres.is_empty() {
            return;
        }
        let mut list = VerletList::half(1.02 * 2.0 * r_max, 0.0);
        list.set_groups(&spheres.iter().map(|s| s.0 as u32).collect::<Vec<_>>());
        let centres: Vec<DVec3> = spheres.iter().map(|s| s.1).collect();
        list.build(
            &centres,
            &Boundary {
                lo: DVec3::new(0.0, 0.0, f64::NEG_INFINITY),
                hi: DVec3::new(lx, ly, f64::INFINITY),
                periodic: [true, true, false],
            },
        );
        for (a, &(ka, ca, ra)) in spheres.iter().enumerate() {
            for &b in list.of(a) {
                let (kb, cb, rb) = spheres[b as usize];
                let mut d = ca - cb;
                d.x -= (d.x / lx).round() * lx;
                d.y -= (d.y / ly).round() * ly;
                if d.length() < 1.02 * (ra + rb) {
                    let (x, y) = (root(&mut parent, ka), root(&mut parent, kb));
                    parent[x] = y;
                }
            }
        }
        // Per cluster: lowest bottom, highest top.
        let mut extent = vec![(f64::INFINITY, f64::NEG_INFINITY); carriers.len()];
        for &(k, c, r) in &spheres {
            let g = root(&mut parent, k);
            extent[g].0 = extent[g].0.min(c.z - r);
            extent[g].1 = extent[g].1.max(c.z + r);
        }
        let (mut reach, mut rooted) = (0.0, 0);
        for k in 0..carriers.len() {
            if root(&mut parent, k) != k {
                continue;
            }
            s.chains += 1;
            let (bottom, top) = extent[k];
            let at_shell = top > self.shell - r_max;
            if at_shell {
                rooted += 1;
                reach += self.shell - bottom;
                if bottom < self.belt + r_max {
                    s.bridges += 1;
                }
            }
        }
        s.brush_height = if rooted > 0 {
            reach / rooted as f64
        } else {
            0.0
        };
    }
}

/// nip.csv: [`NipSample::COLUMNS`] every `every` steps.
pub struct NipCsv {
    pub probe: NipProbe,
    writer: CsvWriter,
    every: u64,
}

impl NipCsv {
    pub fn create(
        path: &Path,
        provenance: &Provenance,
        probe: NipProbe,
        every: u64,
        append: bool,
    ) -> Result<Self, MdError> {
        let writer = if append {
            CsvWriter::append(path, NipSample::COLUMNS.len())?
        } else {
            CsvWriter::create(path, provenance, &NipSample::COLUMNS.map(String::from), &[])?
        };
        Ok(NipCsv {
            probe,
            writer,
            every,
        })
    }
}

impl Observer<RigidDynamics> for NipCsv {
    fn every(&self) -> u64 {
        self.every
    }

    fn observe(&mut self, d: &RigidDynamics, _: &RigidSample) -> Result<(), MdError> {
        let s = self.probe.measure(&d.bodies);
        Ok(self.writer.row(&[
            d.bodies.time,
            s.developed as f64,
            s.mass_image,
            s.mass_background,
            s.charge_image,
            s.charge_background,
            s.neutralised,
            s.chains as f64,
            s.bridges as f64,
            s.brush_height,
            s.free_volume,
        ])?)
    }

    fn files(&self) -> Vec<String> {
        vec![self.writer.path().display().to_string()]
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use glam::DVec3;
    use mote_geom::{DE, E};
    use mote_md::rigid::{BodyTemplate, RigidBodies};

    use super::NipProbe;

    /// A one-sphere template ([`BodyTemplate::sphere`]) with a charge.
    fn sphere(radius: f64, density: f64, charge: f64) -> std::sync::Arc<BodyTemplate> {
        let mut t = BodyTemplate::sphere(radius, density).unwrap();
        std::sync::Arc::get_mut(&mut t).unwrap().charge = charge;
        t
    }

    #[test]
    fn probe_counts_developed_toner_and_the_brush() {
        let mut b = RigidBodies::new();
        let carrier = b.add_template(sphere(2.0, 1.0, 0.0));
        let toner = b.add_template(sphere(0.5, 3.0, -0.1));
        let at = |x: f64, y: f64, z: f64| E::new(DVec3::ZERO, DVec3::new(x, y, z));
        // Box 20 × 10, belt at z = 1, shell at z = 15; image [2, 8) moving at 1.
        // Toner touching the belt: two on the image (x = 3, 7.5 at t = 0.5,
        // i.e. 2.5 and 7 in the belt's frame), one on the background; one
        // floating.
        for (x, z) in [(3.0, 1.5), (7.5, 1.52), (15.0, 1.5), (5.0, 6.0)] {
            b.push(toner, at(x, 5.0, z), DE::ZERO);
        }
        // A chain of three carriers hanging from the shell across the periodic
        // boundary in x (touching only through it), a bridge of four reaching
        // the belt at x = 12, and a lone carrier in the middle.
        for (x, z) in [(0.5, 13.0), (19.6, 9.1), (0.5, 5.2)] {
            b.push(carrier, at(x, 5.0, z), DE::ZERO);
        }
        for z in [13.0, 9.0, 5.0, 2.0] {
            b.push(carrier, at(12.0, 5.0, z), DE::ZERO);
        }
        b.push(carrier, at(5.5, 5.0, 9.0), DE::ZERO);
        b.time = 0.5;
        let probe = NipProbe {
            toner,
            carrier,
            belt: 1.0,
            shell: 15.0,
            lo: DVec3::ZERO,
            hi: DVec3::new(20.0, 10.0, 15.0),
            patches: vec![[2.0, 8.0]],
            speed: 1.0,
            contrast: 0.02,
            window: None,
        };
        let s = probe.measure(&b);
        assert_eq!(s.developed, 3);
        let m = 3.0 * 4.0 / 3.0 * PI * 0.125;
        let (a_image, a_back) = (6.0 * 10.0, 14.0 * 10.0);
        assert!((s.mass_image - 2.0 * m / a_image).abs() < 1e-3 * s.mass_image);
        assert!((s.mass_background - m / a_back).abs() < 1e-3 * s.mass_background);
        assert!((s.charge_image + 0.2 / a_image).abs() < 1e-12);
        assert!((s.neutralised - 0.2 / a_image / 0.02).abs() < 1e-12);
        // Clusters: the chain, the bridge, the lone carrier.
        assert_eq!(s.chains, 3, "{s:?}");
        assert_eq!(s.bridges, 1, "{s:?}");
        // Reach of the two clusters at the shell: the chain's lowest sphere
        // bottom is 5.2 − 2, the bridge's 2 − 2.
        let expected = ((15.0 - 3.2) + (15.0 - 0.0)) / 2.0;
        assert!((s.brush_height - expected).abs() < 1e-12, "{s:?}");
        let solids = 4.0 * 4.0 / 3.0 * PI * 0.125 + 8.0 * 4.0 / 3.0 * PI * 8.0;
        let free = 1.0 - solids / (200.0 * 14.0);
        assert!(
            (s.free_volume - free).abs() < 1e-3,
            "{} against {free}",
            s.free_volume
        );

        // A window over x in [0, 10): the image there is [2.5, 8.5) at
        // t = 0.5; the two toner on it are inside, the background one not;
        // three toner and three carriers are centred in it.
        let window = NipProbe {
            window: Some([0.0, 10.0]),
            ..probe.clone()
        };
        let w = window.measure(&b);
        assert_eq!(w.developed, 2);
        assert!((w.mass_image - 2.0 * m / 60.0).abs() < 1e-3 * w.mass_image);
        assert_eq!(w.mass_background, 0.0);
        let solids = 3.0 * 4.0 / 3.0 * PI * 0.125 + 3.0 * 4.0 / 3.0 * PI * 8.0;
        assert!(
            (w.free_volume - (1.0 - solids / 1400.0)).abs() < 1e-3,
            "{w:?}"
        );
        // The image's length in a window, across the period's end too.
        assert!((window.image_in([0.0, 10.0], 0.5) - 6.0).abs() < 1e-12);
        assert!((window.image_in([15.0, 20.0], 17.0) - 1.0).abs() < 1e-12);
        assert!((window.image_in([0.0, 10.0], 17.0) - 5.0).abs() < 1e-12);
    }
}
