//! Mutze's Euclidean geometry (seed 000): placements E(r, a), velocities
//! dE(ω, v), inertia I, and the exponential and logarithm between them.
