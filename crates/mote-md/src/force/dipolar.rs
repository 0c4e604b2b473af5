//! Dipolar interactions (in progress).
