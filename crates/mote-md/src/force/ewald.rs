//! Ewald summation for charges and point dipoles in cubic periodic boxes.
