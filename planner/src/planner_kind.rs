//! Which planner a vehicle runs: the kinds PF-CS, PF-SP, PF-SP-EQ10, PF-ISO and PF-ISO-PRED,
//! and their kebab-case names (what the `--planner` option and a scenario's `planner` key take).

use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::PlannerError;

/// Which planner a vehicle runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PlannerKind {
    /// PF path, constant speed V_target.
    PfCs,
    /// PF path, risk-aware speed planning without V2V (the paper's baseline).
    PfSp,
    /// PF path, Eq. 10 with w3 = 0 (a control planner).
    PfSpEq10,
    /// PF path, interactive speed optimisation with the shared local paths (Eq. 10).
    PfIso,
    /// Like PF-ISO with the others' paths predicted (no V2V).
    PfIsoPred,
}

impl PlannerKind {
    /// Every kind, in a fixed order.
    pub const ALL: [PlannerKind; 5] = [
        PlannerKind::PfCs,
        PlannerKind::PfSp,
        PlannerKind::PfSpEq10,
        PlannerKind::PfIso,
        PlannerKind::PfIsoPred,
    ];

    /// The kebab-case name (`pf-cs`, `pf-sp`, `pf-sp-eq10`, `pf-iso`, `pf-iso-pred`).
    pub fn name(&self) -> &'static str {
        match self {
            PlannerKind::PfCs => "pf-cs",
            PlannerKind::PfSp => "pf-sp",
            PlannerKind::PfSpEq10 => "pf-sp-eq10",
            PlannerKind::PfIso => "pf-iso",
            PlannerKind::PfIsoPred => "pf-iso-pred",
        }
    }

    /// Whether it uses the interaction term of Eq. 10 (and so the `interaction_*` parameters).
    pub fn is_interactive(&self) -> bool {
        matches!(self, PlannerKind::PfIso | PlannerKind::PfIsoPred)
    }
}

impl std::fmt::Display for PlannerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for PlannerKind {
    type Err = PlannerError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        PlannerKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| PlannerError::UnknownName {
                what: "planner".into(),
                given: s.into(),
                valid: PlannerKind::ALL.map(|k| k.name()).join(", "),
            })
    }
}
