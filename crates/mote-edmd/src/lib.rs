//! Event-driven molecular dynamics of hard spheres (D = 3) and disks (D = 2).
