//! Time-stepped dynamics.
