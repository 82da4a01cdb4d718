//! The prescribed-speed driver: the path of a planner, the speeds of a time → speed profile.
//! It tests a speed profile's effect (e.g. the paper's pre-braking) on the winding without the
//! speed optimiser.

use mergesim_types::{Behaviour, BehaviourError, Decision, GridSpec, Observation, SharedLocalPath};
use planner::speed_profile::SpeedProfile;
use planner::speed_profile::retime_path;

/// A planner's path at prescribed speeds (module doc).
pub struct PrescribedSpeed {
    /// The planner whose path is followed.
    pub path_planner: Box<dyn Behaviour>,
    /// The speeds.
    pub profile: SpeedProfile,
}

impl Behaviour for PrescribedSpeed {
    /// The path planner's decision re-timed to the profile (its broadcast too); a fallback is
    /// passed on unchanged.
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        let mut decision = self.path_planner.plan(obs)?;
        if decision.fallback.is_none() {
            retime_path(&mut decision.path, &self.profile);
            if let Some(message) = &decision.broadcast {
                decision.broadcast = Some(SharedLocalPath::from_path(
                    message.vehicle_id,
                    message.stamp_s,
                    message.shape,
                    message.speed_mps,
                    &decision.path,
                ));
            }
        }
        Ok(decision)
    }

    fn potential_field(&self, obs: &Observation<'_>, spec: &GridSpec) -> Option<Vec<f64>> {
        self.path_planner.potential_field(obs, spec)
    }
}
