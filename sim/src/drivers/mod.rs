//! The simulator's own behaviours: a lane-keeping driver without a planner, a human driver
//! (Intelligent Driver Model car following with lane keeping) and the prescribed-speed driver
//! (a planner's path at a prescribed time → speed profile). The potential-field planners are the
//! planner crate's; a user's planner is registered by name (`crate::registry`).

pub(crate) mod idm_driver;
pub(crate) mod lane_keeping;
pub(crate) mod prescribed_speed;

pub use idm_driver::IdmDriver;
pub use lane_keeping::{LaneKeeping, lane_path};
pub(crate) use prescribed_speed::PrescribedSpeed;
