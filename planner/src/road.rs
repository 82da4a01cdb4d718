//! Geometry of the merge road (paper Sec. III-A-2, the piecewise lower edge of Eq. 3), shared
//! with the simulator's road collider: see [`mergesim_types::road`].

pub use mergesim_types::road::*;
