//! The octree shared by range queries and Barnes–Hut multipole sums.
