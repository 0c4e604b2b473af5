//! Observables of magnetic (dipolar) particles and the theories they are
//! compared with: magnetisation along the field, the Langevin function,
//! the modified mean-field theory of Ivanov & Kuznetsova, head-to-tail
//! chains and clusters, and the orientation autocorrelation.

use glam::DVec3;

use crate::boundary::Boundary;
use crate::force::dipolar::dipole_pair;
use crate::neighbor::CellGrid;

/// The Langevin function L(ξ) = coth ξ − 1/ξ: the mean ⟨cos θ⟩ of a free
/// dipole in a field at Langevin parameter ξ = μ₀ m H / k_BT. Odd; the
/// series ξ/3 − ξ³/45 + 2ξ⁵/945 − ξ⁷/4725 below |ξ| = 10⁻².
pub fn langevin(xi: f64) -> f64 {
    if xi.abs() < 1e-2 {
        let x2 = xi * xi;
        xi * (1.0 / 3.0 - x2 * (1.0 / 45.0 - x2 * (2.0 / 945.0 - x2 / 4725.0)))
    } else {
        1.0 / xi.tanh() - 1.0 / xi
    }
}

/// L′(ξ) = 1/ξ² − 1/sinh² ξ (1/3 − ξ²/15 + 2ξ⁴/189 below |ξ| = 10⁻²).
pub fn langevin_derivative(xi: f64) -> f64 {
    if xi.abs() < 1e-2 {
        let x2 = xi * xi;
        1.0 / 3.0 - x2 / 15.0 + 2.0 * x2 * x2 / 189.0
    } else {
        1.0 / (xi * xi) - 1.0 / xi.sinh().powi(2)
    }
}

/// The Langevin susceptibility χ_L = μ₀ n m² / (3 k_BT) = 8 λ φ of a
/// suspension of hard spheres of diameter σ at volume fraction φ = nπσ³/6
/// with coupling constant λ = μ₀ m² / (4π σ³ k_BT).
pub fn langevin_susceptibility(lambda: f64, volume_fraction: f64) -> f64 {
    8.0 * lambda * volume_fraction
}

/// Reduced magnetisation M/M_s of the second-order modified mean-field
/// theory (MMF2) of Ivanov & Kuznetsova, Phys. Rev. E 64, 041405 (2001),
/// Eq. (11) in the form of ESPResSo's ferrofluid tutorial:
/// M/M_s = L(ξ_e), ξ_e = ξ + χ_L L(ξ) + (χ_L²/16) L(ξ) L′(ξ).
pub fn mmf2_magnetisation(xi: f64, chi_langevin: f64) -> f64 {
    let l = langevin(xi);
    langevin(
        xi + chi_langevin * l + chi_langevin * chi_langevin / 16.0 * l * langevin_derivative(xi),
    )
}

/// MMF2 initial susceptibility χ = χ_L (1 + χ_L/3 + χ_L²/144)
/// (Ivanov & Kuznetsova 2001).
pub fn mmf2_initial_susceptibility(chi_langevin: f64) -> f64 {
    chi_langevin * (1.0 + chi_langevin / 3.0 + chi_langevin * chi_langevin / 144.0)
}

/// Total moment Σ m_i.
pub fn total_moment(dipoles: &[DVec3]) -> DVec3 {
    dipoles.iter().copied().sum()
}

/// Reduced magnetisation along a direction: Σ m_i·ĥ / Σ |m_i| (1 when all
/// moments point along ĥ; the Langevin function for free dipoles).
pub fn reduced_magnetisation(dipoles: &[DVec3], direction: DVec3) -> f64 {
    let h = direction.normalize();
    let (along, saturation) = dipoles
        .iter()
        .fold((0.0, 0.0), |(a, s), m| (a + m.dot(h), s + m.length()));
    if saturation > 0.0 {
        along / saturation
    } else {
        0.0
    }
}

/// When two dipoles count as bonded in a chain: head to tail, near and
/// bound. Particles i and j are bonded if
/// (1) their distance r is below `max_distance`,
/// (2) their dipolar pair energy (004 Eq. 8) is below `max_energy`, and
/// (3) both moments point the same way along the bond,
///     (m_i·r)(m_j·r) > 0 (head to tail, not side by side).
///
/// [`BondCriterion::head_to_tail`] takes r < 1.3 σ and U < −1.5 k_BT
/// (as in the chain analyses of Weis & Levesque and of Holm & Weis, Curr.
/// Opin. Colloid Interface Sci. 10, 133 (2005), a pair bound more strongly
/// than the thermal energy at near contact).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BondCriterion {
    pub max_distance: f64,
    pub max_energy: f64,
    /// μ₀ of the unit system (see `force::dipolar::vacuum_permeability`).
    pub mu0: f64,
}

impl BondCriterion {
    /// r < 1.3 σ, U_dd < −1.5 k_BT, head to tail.
    pub fn head_to_tail(sigma: f64, kt: f64, mu0: f64) -> Self {
        Self {
            max_distance: 1.3 * sigma,
            max_energy: -1.5 * kt,
            mu0,
        }
    }

    /// Whether the pair at separation d = r_i − r_j is bonded.
    pub fn bonded(&self, d: DVec3, mi: DVec3, mj: DVec3) -> bool {
        let r2 = d.length_squared();
        if r2 >= self.max_distance * self.max_distance || r2 == 0.0 {
            return false;
        }
        if mi.dot(d) * mj.dot(d) <= 0.0 {
            return false;
        }
        dipole_pair(self.mu0 / (4.0 * std::f64::consts::PI), d, 1.0 / r2, mi, mj).0
            < self.max_energy
    }
}

/// Clusters of bonded dipoles (connected components of the bond graph;
/// chains when, as usual, each particle has at most two bonds), each a
/// sorted list of particle indices, largest first; single particles are
/// clusters of size 1. Minimum image on periodic axes.
pub fn clusters(
    position: &[DVec3],
    dipoles: &[DVec3],
    boundary: &Boundary,
    criterion: &BondCriterion,
) -> Vec<Vec<usize>> {
    let n = position.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    if n > 0 {
        let grid = CellGrid::new(position, boundary, criterion.max_distance);
        let image = boundary.image();
        for i in 0..n {
            if dipoles[i] == DVec3::ZERO {
                continue;
            }
            grid.for_each_candidate(position[i], |j| {
                if j > i {
                    let d = image.apply(boundary.wrap(position[i]) - boundary.wrap(position[j]));
                    if criterion.bonded(d, dipoles[i], dipoles[j]) {
                        let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                        if a != b {
                            parent[a.max(b)] = a.min(b);
                        }
                    }
                }
            });
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for i in 0..n {
        let r = root(&mut parent, i);
        groups.entry(r).or_default().push(i);
    }
    let mut out: Vec<Vec<usize>> = groups.into_values().collect();
    out.sort_by(|a, b| b.len().cmp(&a.len()).then(a[0].cmp(&b[0])));
    out
}

/// Cluster statistics: `counts[s]` clusters of size s (s ≥ 1), the
/// number-averaged and weight-averaged sizes, and the fraction of particles
/// in clusters of two or more.
#[derive(Debug, Clone, PartialEq)]
pub struct ClusterStatistics {
    pub counts: Vec<usize>,
    pub mean_size: f64,
    pub weight_mean_size: f64,
    pub fraction_bonded: f64,
}

impl ClusterStatistics {
    pub fn of(clusters: &[Vec<usize>]) -> Self {
        let largest = clusters.iter().map(|c| c.len()).max().unwrap_or(0);
        let mut counts = vec![0usize; largest + 1];
        for c in clusters {
            counts[c.len()] += 1;
        }
        let n: usize = clusters.iter().map(|c| c.len()).sum();
        let sq: usize = clusters.iter().map(|c| c.len() * c.len()).sum();
        let bonded: usize = clusters
            .iter()
            .filter(|c| c.len() > 1)
            .map(|c| c.len())
            .sum();
        let nf = n.max(1) as f64;
        Self {
            counts,
            mean_size: n as f64 / clusters.len().max(1) as f64,
            weight_mean_size: sq as f64 / nf,
            fraction_bonded: bonded as f64 / nf,
        }
    }
}

/// The orientation autocorrelation C(t) = ⟨u_i(0)·u_i(t)⟩ over the particles
/// with a moment (u = m/|m|). Free rotational diffusion gives exp(−2 D_r t).
#[derive(Debug, Clone, PartialEq)]
pub struct OrientationCorrelation {
    initial: Vec<DVec3>,
}

impl OrientationCorrelation {
    /// Remembers the orientations at the time origin.
    pub fn start(dipoles: &[DVec3]) -> Self {
        Self {
            initial: dipoles.iter().map(|m| m.normalize_or_zero()).collect(),
        }
    }

    /// C at the present orientations.
    pub fn value(&self, dipoles: &[DVec3]) -> f64 {
        let (mut sum, mut count) = (0.0, 0usize);
        for (u0, m) in self.initial.iter().zip(dipoles) {
            if *u0 != DVec3::ZERO {
                sum += u0.dot(m.normalize_or_zero());
                count += 1;
            }
        }
        if count > 0 {
            sum / count as f64
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn langevin_function_and_series_agree() {
        for x in [1e-3, 9.9e-3, 1.01e-2, 0.5, 3.0, -2.0] {
            let exact = 1.0 / f64::tanh(x) - 1.0 / x;
            assert!((langevin(x) - exact).abs() < 1e-12, "{x}");
            let h = 1e-5;
            let fd = (langevin(x + h) - langevin(x - h)) / (2.0 * h);
            assert!((langevin_derivative(x) - fd).abs() < 1e-8, "{x}");
        }
        assert!((langevin(1e-3) - (1e-3 / 3.0 - 1e-9 / 45.0)).abs() < 1e-16);
        assert_eq!(langevin(0.0), 0.0);
        // MMF2 reduces to Langevin without interactions; its slope at 0 is χ/(3 χ_L) per ξ.
        assert_eq!(mmf2_magnetisation(2.0, 0.0), langevin(2.0));
        let chi_l = 0.6288;
        let slope = mmf2_magnetisation(1e-4, chi_l) / 1e-4;
        assert!((slope * 3.0 * chi_l - mmf2_initial_susceptibility(chi_l) * 1.0).abs() < 1e-6);
    }
}
