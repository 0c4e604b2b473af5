//! Rigid bodies made of overlapping spheres, moved by Mutze's Fast Rigid
//! Bodies Integrator (seed 000).
