//! The vehicles' goals (`crate::goal`), checked every log period, and a vehicle leaving the
//! map, which ends the run with an event.

use mergesim_types::VehicleState;
use vehicles::Kinematics;

use super::World;
use crate::error::SimError;
use crate::event::SimEvent;
use crate::goal::GoalOutcome;

impl World {
    /// Checks the goal of every vehicle that has one and has not reached it yet; logs the
    /// instant it is reached as an event.
    pub(super) fn check_goals(&mut self, t_s: f64, kins: &[Kinematics]) -> Result<(), SimError> {
        let mut reached = Vec::new();
        let mut reached_at = Vec::new();
        for (i, (agent, k)) in self.agents.iter().zip(kins).enumerate() {
            let Some(goal) = &agent.spec.goal else {
                continue;
            };
            // Vehicles spawned after the world was built have no slot (and no goal).
            let Some(slot) = self.goal_times.get(i) else {
                continue;
            };
            if slot.is_some() {
                continue;
            }
            if goal.is_reached(t_s, &VehicleState::from(k), &self.lanes) {
                reached_at.push(i);
                reached.push(SimEvent::GoalReached {
                    t_s,
                    vehicle: agent.spec.name.clone(),
                    x_m: k.x_m,
                    y_m: k.y_m,
                    speed_mps: k.speed_mps,
                });
            }
        }
        for i in reached_at {
            if let Some(slot) = self.goal_times.get_mut(i) {
                *slot = Some(t_s);
            }
        }
        for event in reached {
            self.event(event)?;
        }
        Ok(())
    }

    /// The goals at the end of the run, in vehicle order (vehicles without a goal left out).
    pub(super) fn goal_outcomes(&self) -> Vec<GoalOutcome> {
        self.agents
            .iter()
            .zip(&self.goal_times)
            .filter(|(a, _)| a.spec.goal.is_some())
            .map(|(a, t)| GoalOutcome {
                vehicle: a.spec.name.clone(),
                reached: t.is_some(),
                time_s: *t,
            })
            .collect()
    }

    /// Ends the run because `vehicle` left the map at `t_s` past the open end of `lane`: an
    /// event (not an error); the run's outcome covers the time up to it.
    pub(super) fn leave_map(
        &mut self,
        vehicle: &str,
        t_s: f64,
        lane: mergesim_types::lanes::LaneId,
    ) -> Result<(), SimError> {
        self.left_map = true;
        self.event(SimEvent::LeftMap {
            t_s,
            vehicle: vehicle.to_string(),
            lane,
        })
    }
}
