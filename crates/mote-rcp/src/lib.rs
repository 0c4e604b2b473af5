//! Size distributions and the rod-packing estimator of random close packing.
