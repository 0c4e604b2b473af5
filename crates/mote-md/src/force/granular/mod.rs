//! Granular contacts (discrete element method): Hertz–Mindlin spheres with
//! Tsuji damping, Coulomb friction, rolling resistance and adhesion
//! ([`law`]), between spheres ([`GranularContacts`]) and against walls
//! ([`GranularWalls`]). Physics: seed 000 (Hertz contacts, damping,
//! friction, adhesion, walls).

pub mod batch;
pub mod contacts;
pub mod history;
pub mod law;
pub mod pairs;
pub mod walls;

pub use contacts::GranularContacts;
pub use history::PairHistories;
pub use law::{ContactForce, ContactLaw, Damping, History, Material};
pub use pairs::ContactPairs;
pub use walls::{GranularWalls, Wall, WallShape};
