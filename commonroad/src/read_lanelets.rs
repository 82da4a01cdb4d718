//! The lanelets of a CommonRoad file: bounds, links, neighbours, types and speed limits
//! (2018b's `speedLimit`, 2020a's maximum-speed traffic signs).

use std::collections::HashMap;

use roxmltree::Node;

use crate::error::ErrorKind;
use crate::model::{Adjacent, DrivingDir, FormatVersion, Lanelet};
use crate::read::{R, Reader, child, children};

impl Reader<'_, '_> {
    /// 2020a traffic signs giving a maximum speed (German `274`, US `R2-1`): sign id → m/s.
    pub(crate) fn speed_signs(&self, root: Node) -> R<HashMap<i64, f64>> {
        let mut out = HashMap::new();
        for sign in children(root, "trafficSign") {
            let id = self.id_attr(sign, "id", Some("trafficSign"))?;
            let owner = format!("trafficSign {id}");
            for el in children(sign, "trafficSignElement") {
                let code = child(el, "trafficSignID")
                    .and_then(|c| c.text())
                    .unwrap_or("")
                    .trim();
                if matches!(code, "274" | "R2-1")
                    && let Some(v) = child(el, "additionalValue")
                {
                    out.insert(id, self.positive(v, &owner)?);
                }
            }
        }
        Ok(out)
    }

    pub(crate) fn reference(&self, node: Node, owner: &str, known: &HashMap<i64, u32>) -> R<i64> {
        let id = self.id_attr(node, "ref", Some(owner))?;
        if known.contains_key(&id) {
            Ok(id)
        } else {
            Err(self.err(
                node,
                Some(owner),
                ErrorKind::UnknownLanelet {
                    field: node.tag_name().name().to_owned(),
                    target: id,
                },
            ))
        }
    }

    pub(crate) fn bound(&self, node: Node, owner: &str) -> R<Vec<[f64; 2]>> {
        children(node, "point")
            .map(|p| self.point(p, owner))
            .collect()
    }

    pub(crate) fn adjacent(
        &self,
        node: Node,
        name: &str,
        owner: &str,
        known: &HashMap<i64, u32>,
    ) -> R<Option<Adjacent>> {
        let Some(a) = child(node, name) else {
            return Ok(None);
        };
        let id = self.reference(a, owner, known)?;
        let driving_dir = match a.attribute("drivingDir").map(str::trim) {
            Some("same") => DrivingDir::Same,
            Some("opposite") => DrivingDir::Opposite,
            other => {
                return Err(self.err(
                    a,
                    Some(owner),
                    ErrorKind::BadValue {
                        field: format!("{name}.drivingDir"),
                        reason: format!("{other:?} (expected \"same\" or \"opposite\")"),
                    },
                ));
            }
        };
        Ok(Some(Adjacent { id, driving_dir }))
    }

    pub(crate) fn lanelet(
        &self,
        node: Node,
        format: FormatVersion,
        known: &HashMap<i64, u32>,
        speed_signs: &HashMap<i64, f64>,
    ) -> R<Lanelet> {
        let id = self.id_attr(node, "id", Some("lanelet"))?;
        let owner = format!("lanelet {id}");
        let left_bound_m = self.bound(self.req(node, "leftBound", &owner)?, &owner)?;
        let right_bound_m = self.bound(self.req(node, "rightBound", &owner)?, &owner)?;
        if left_bound_m.len() != right_bound_m.len() || left_bound_m.len() < 2 {
            let kind = if left_bound_m.len() == right_bound_m.len() {
                ErrorKind::BadValue {
                    field: "leftBound".into(),
                    reason: format!("{} points (at least 2 needed)", left_bound_m.len()),
                }
            } else {
                ErrorKind::BoundPointCounts {
                    left: left_bound_m.len(),
                    right: right_bound_m.len(),
                }
            };
            return Err(self.err(node, Some(&owner), kind));
        }
        let refs = |name: &str| -> R<Vec<i64>> {
            children(node, name)
                .map(|c| self.reference(c, &owner, known))
                .collect()
        };
        let mut speed_limit_mps = child(node, "speedLimit")
            .map(|s| self.positive(s, &owner))
            .transpose()?;
        if format == FormatVersion::V2020a {
            for r in children(node, "trafficSignRef") {
                let sign = self.id_attr(r, "ref", Some(&owner))?;
                if let Some(&v) = speed_signs.get(&sign) {
                    speed_limit_mps = Some(speed_limit_mps.map_or(v, |s: f64| s.min(v)));
                }
            }
        }
        Ok(Lanelet {
            id,
            line: self.line(node),
            left_bound_m,
            right_bound_m,
            predecessors: refs("predecessor")?,
            successors: refs("successor")?,
            adjacent_left: self.adjacent(node, "adjacentLeft", &owner, known)?,
            adjacent_right: self.adjacent(node, "adjacentRight", &owner, known)?,
            lanelet_types: children(node, "laneletType")
                .filter_map(|t| t.text())
                .map(|t| t.trim().to_owned())
                .collect(),
            speed_limit_mps,
        })
    }
}
