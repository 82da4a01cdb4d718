//! The XML reader: roxmltree's document, walked element by element. Every error carries the
//! file, the line of the element at fault (roxmltree keeps node positions) and the id of the
//! lanelet, obstacle or planning problem it belongs to.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use roxmltree::{Document, Node};

use crate::error::{CommonRoadError, ErrorKind};
use crate::limits::{MAX_FILE_BYTES, MAX_LANELETS, MAX_OBSTACLES, MAX_STATES_PER_OBSTACLE};
use crate::model::{
    FormatVersion, Obstacle, PlanningProblem, Position, Scenario, Shape, State, Value,
};

/// Reads a CommonRoad XML file (format 2020a or 2018b).
///
/// # Errors
/// [`CommonRoadError`] naming the file, the line and the element: unreadable or too large
/// files, malformed XML, an unsupported format version, missing or non-numeric values, unknown
/// lanelet references, bounds with different point counts, more lanelets or obstacles than the
/// limits.
pub fn read_file(path: &Path) -> Result<Scenario, CommonRoadError> {
    let at = |kind| CommonRoadError {
        path: path.to_path_buf(),
        line: None,
        element: None,
        kind,
    };
    let bytes = std::fs::metadata(path)
        .map_err(|e| at(ErrorKind::Io(e)))?
        .len();
    if bytes > MAX_FILE_BYTES {
        return Err(at(ErrorKind::TooLarge {
            bytes,
            max: MAX_FILE_BYTES,
        }));
    }
    let text = std::fs::read_to_string(path).map_err(|e| at(ErrorKind::Io(e)))?;
    read_str(path, &text)
}

/// Reads CommonRoad XML from a string; `path` only names the source in errors.
///
/// # Errors
/// As [`read_file`].
pub fn read_str(path: &Path, text: &str) -> Result<Scenario, CommonRoadError> {
    let doc = Document::parse(text).map_err(|e| CommonRoadError {
        path: path.to_path_buf(),
        line: Some(e.pos().row),
        element: None,
        kind: ErrorKind::Xml(e.to_string()),
    })?;
    Reader {
        path: path.to_path_buf(),
        doc: &doc,
    }
    .scenario()
}

pub(crate) struct Reader<'a, 'i> {
    path: PathBuf,
    doc: &'a Document<'i>,
}

pub(crate) type R<T> = Result<T, CommonRoadError>;

pub(crate) fn children<'a, 'i>(
    node: Node<'a, 'i>,
    name: &'a str,
) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == name)
}

pub(crate) fn child<'a, 'i>(node: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
    node.children()
        .find(|c| c.is_element() && c.tag_name().name() == name)
}

impl<'a, 'i> Reader<'a, 'i> {
    pub(crate) fn line(&self, node: Node) -> u32 {
        self.doc.text_pos_at(node.range().start).row
    }

    pub(crate) fn err(&self, node: Node, owner: Option<&str>, kind: ErrorKind) -> CommonRoadError {
        CommonRoadError {
            path: self.path.clone(),
            line: Some(self.line(node)),
            element: owner.map(str::to_owned),
            kind,
        }
    }

    pub(crate) fn req<'n>(&self, node: Node<'n, 'i>, name: &str, owner: &str) -> R<Node<'n, 'i>> {
        child(node, name).ok_or_else(|| {
            self.err(
                node,
                Some(owner),
                ErrorKind::Missing {
                    what: format!("<{name}> in <{}>", node.tag_name().name()),
                },
            )
        })
    }

    pub(crate) fn number(&self, node: Node, owner: &str) -> R<f64> {
        let text = node.text().unwrap_or("").trim();
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.err(
                node,
                Some(owner),
                ErrorKind::BadNumber {
                    field: node.tag_name().name().to_owned(),
                    text: text.to_owned(),
                },
            )),
        }
    }

    pub(crate) fn id_attr(&self, node: Node, attr: &str, owner: Option<&str>) -> R<i64> {
        let text = node.attribute(attr).ok_or_else(|| {
            self.err(
                node,
                owner,
                ErrorKind::Missing {
                    what: format!("attribute {attr} of <{}>", node.tag_name().name()),
                },
            )
        })?;
        text.trim().parse::<i64>().map_err(|_| {
            self.err(
                node,
                owner,
                ErrorKind::BadValue {
                    field: format!("{}.{attr}", node.tag_name().name()),
                    reason: format!("\"{text}\" is not an integer"),
                },
            )
        })
    }

    pub(crate) fn point(&self, node: Node, owner: &str) -> R<[f64; 2]> {
        let x = self.number(self.req(node, "x", owner)?, owner)?;
        let y = self.number(self.req(node, "y", owner)?, owner)?;
        Ok([x, y])
    }

    fn value(&self, node: Node, owner: &str) -> R<Value> {
        if let Some(exact) = child(node, "exact") {
            return Ok(Value::Exact(self.number(exact, owner)?));
        }
        let start = self.number(self.req(node, "intervalStart", owner)?, owner)?;
        let end = self.number(self.req(node, "intervalEnd", owner)?, owner)?;
        if start > end {
            return Err(self.err(
                node,
                Some(owner),
                ErrorKind::BadValue {
                    field: node.tag_name().name().to_owned(),
                    reason: format!("interval start {start} > end {end}"),
                },
            ));
        }
        Ok(Value::Interval { start, end })
    }

    fn opt_value(&self, node: Node, name: &str, owner: &str) -> R<Option<Value>> {
        child(node, name).map(|c| self.value(c, owner)).transpose()
    }

    pub(crate) fn positive(&self, node: Node, owner: &str) -> R<f64> {
        let v = self.number(node, owner)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(
                node,
                Some(owner),
                ErrorKind::BadValue {
                    field: node.tag_name().name().to_owned(),
                    reason: format!("{v} must be positive"),
                },
            ))
        }
    }

    /// A `<rectangle>`, `<circle>` or `<polygon>`.
    fn shape(&self, node: Node, owner: &str) -> R<Option<Shape>> {
        let center = |n: Node| -> R<[f64; 2]> {
            child(n, "center").map_or(Ok([0.0, 0.0]), |c| self.point(c, owner))
        };
        Ok(Some(match node.tag_name().name() {
            "rectangle" => Shape::Rectangle {
                length_m: self.positive(self.req(node, "length", owner)?, owner)?,
                width_m: self.positive(self.req(node, "width", owner)?, owner)?,
                orientation_rad: child(node, "orientation")
                    .map_or(Ok(0.0), |o| self.number(o, owner))?,
                center_m: center(node)?,
            },
            "circle" => Shape::Circle {
                radius_m: self.positive(self.req(node, "radius", owner)?, owner)?,
                center_m: center(node)?,
            },
            "polygon" => Shape::Polygon {
                vertices_m: children(node, "point")
                    .map(|p| self.point(p, owner))
                    .collect::<R<_>>()?,
            },
            _ => return Ok(None),
        }))
    }

    fn position(&self, node: Node, owner: &str) -> R<Position> {
        if let Some(p) = child(node, "point") {
            return Ok(Position::Point(self.point(p, owner)?));
        }
        let lanelets: Vec<i64> = children(node, "lanelet")
            .map(|l| self.id_attr(l, "ref", Some(owner)))
            .collect::<R<_>>()?;
        if !lanelets.is_empty() {
            return Ok(Position::Lanelets(lanelets));
        }
        let mut shapes = Vec::new();
        for c in node.children().filter(Node::is_element) {
            if let Some(s) = self.shape(c, owner)? {
                shapes.push(s);
            }
        }
        if shapes.is_empty() {
            return Err(self.err(
                node,
                Some(owner),
                ErrorKind::Missing {
                    what: "a point, shape or lanelet in <position>".into(),
                },
            ));
        }
        Ok(Position::Shapes(shapes))
    }

    fn state(&self, node: Node, owner: &str) -> R<State> {
        Ok(State {
            line: self.line(node),
            time_step: self.opt_value(node, "time", owner)?,
            position: child(node, "position")
                .map(|p| self.position(p, owner))
                .transpose()?,
            orientation_rad: self.opt_value(node, "orientation", owner)?,
            velocity_mps: self.opt_value(node, "velocity", owner)?,
            acceleration_mps2: self.opt_value(node, "acceleration", owner)?,
            yaw_rate_radps: self.opt_value(node, "yawRate", owner)?,
            slip_angle_rad: self.opt_value(node, "slipAngle", owner)?,
        })
    }

    fn root_attr(&self, root: Node<'a, 'i>, name: &str) -> R<&'a str> {
        root.attribute(name).ok_or_else(|| {
            self.err(
                root,
                None,
                ErrorKind::Missing {
                    what: format!("attribute {name} of <commonRoad>"),
                },
            )
        })
    }

    fn scenario(&self) -> R<Scenario> {
        let root = self.doc.root_element();
        if root.tag_name().name() != "commonRoad" {
            return Err(self.err(
                root,
                None,
                ErrorKind::NotCommonRoad {
                    found: root.tag_name().name().to_owned(),
                },
            ));
        }
        let format = match self.root_attr(root, "commonRoadVersion")?.trim() {
            "2020a" => FormatVersion::V2020a,
            "2018b" => FormatVersion::V2018b,
            other => {
                return Err(self.err(
                    root,
                    None,
                    ErrorKind::UnsupportedVersion {
                        found: other.to_owned(),
                    },
                ));
            }
        };
        let dt_text = self.root_attr(root, "timeStepSize")?;
        let time_step_s = match dt_text.trim().parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => v,
            _ => {
                return Err(self.err(
                    root,
                    None,
                    ErrorKind::BadValue {
                        field: "timeStepSize".into(),
                        reason: format!("\"{dt_text}\" is not a positive number"),
                    },
                ));
            }
        };

        // First pass: the lanelet ids (duplicates and the limit), so references can be checked.
        let lanelet_nodes: Vec<Node> = children(root, "lanelet").collect();
        if lanelet_nodes.len() > MAX_LANELETS {
            return Err(self.err(
                lanelet_nodes[MAX_LANELETS],
                None,
                ErrorKind::TooMany {
                    what: "lanelets",
                    count: lanelet_nodes.len(),
                    max: MAX_LANELETS,
                },
            ));
        }
        let mut lanelet_lines: HashMap<i64, u32> = HashMap::new();
        for &n in &lanelet_nodes {
            let id = self.id_attr(n, "id", Some("lanelet"))?;
            if !(0..=i64::from(u32::MAX)).contains(&id) {
                return Err(self.err(
                    n,
                    Some(&format!("lanelet {id}")),
                    ErrorKind::BadValue {
                        field: "lanelet.id".into(),
                        reason: format!("{id} is outside 0 to {}", u32::MAX),
                    },
                ));
            }
            if let Some(&first_line) = lanelet_lines.get(&id) {
                return Err(self.err(
                    n,
                    Some(&format!("lanelet {id}")),
                    ErrorKind::DuplicateId { id, first_line },
                ));
            }
            lanelet_lines.insert(id, self.line(n));
        }
        let speed_signs = self.speed_signs(root)?;
        let lanelets = lanelet_nodes
            .iter()
            .map(|&n| self.lanelet(n, format, &lanelet_lines, &speed_signs))
            .collect::<R<Vec<_>>>()?;

        let obstacle_nodes: Vec<Node> = root
            .children()
            .filter(|c| {
                c.is_element()
                    && matches!(
                        c.tag_name().name(),
                        "obstacle" | "dynamicObstacle" | "staticObstacle"
                    )
            })
            .collect();
        if obstacle_nodes.len() > MAX_OBSTACLES {
            return Err(self.err(
                obstacle_nodes[MAX_OBSTACLES],
                None,
                ErrorKind::TooMany {
                    what: "obstacles",
                    count: obstacle_nodes.len(),
                    max: MAX_OBSTACLES,
                },
            ));
        }
        let mut dynamic_obstacles = Vec::new();
        let mut static_obstacles = Vec::new();
        let mut obstacle_lines: HashMap<i64, u32> = HashMap::new();
        for n in obstacle_nodes {
            let id = self.id_attr(n, "id", Some(n.tag_name().name()))?;
            let owner = format!("{} {id}", n.tag_name().name());
            if let Some(&first_line) = obstacle_lines.get(&id) {
                return Err(self.err(n, Some(&owner), ErrorKind::DuplicateId { id, first_line }));
            }
            obstacle_lines.insert(id, self.line(n));
            let dynamic = match n.tag_name().name() {
                "dynamicObstacle" => true,
                "staticObstacle" => false,
                _ => {
                    let role = self.req(n, "role", &owner)?;
                    match role.text().unwrap_or("").trim() {
                        "dynamic" => true,
                        "static" => false,
                        other => {
                            return Err(self.err(
                                role,
                                Some(&owner),
                                ErrorKind::BadValue {
                                    field: "role".into(),
                                    reason: format!("\"{other}\" (expected static or dynamic)"),
                                },
                            ));
                        }
                    }
                }
            };
            let o = self.obstacle(n, id, &owner)?;
            if dynamic {
                dynamic_obstacles.push(o);
            } else {
                static_obstacles.push(o);
            }
        }

        let planning_problems = children(root, "planningProblem")
            .map(|n| self.planning_problem(n, &lanelet_lines))
            .collect::<R<Vec<_>>>()?;

        Ok(Scenario {
            format,
            benchmark_id: root.attribute("benchmarkID").unwrap_or("").to_owned(),
            time_step_s,
            lanelets,
            dynamic_obstacles,
            static_obstacles,
            planning_problems,
        })
    }

    fn obstacle(&self, node: Node, id: i64, owner: &str) -> R<Obstacle> {
        let obstacle_type = self
            .req(node, "type", owner)?
            .text()
            .unwrap_or("")
            .trim()
            .to_owned();
        let shape_node = self.req(node, "shape", owner)?;
        let shape = shape_node
            .children()
            .filter(Node::is_element)
            .find_map(|c| self.shape(c, owner).transpose())
            .transpose()?
            .ok_or_else(|| {
                self.err(
                    shape_node,
                    Some(owner),
                    ErrorKind::Missing {
                        what: "a rectangle, circle or polygon in <shape>".into(),
                    },
                )
            })?;
        let initial_state = self.state(self.req(node, "initialState", owner)?, owner)?;
        let mut trajectory = Vec::new();
        if let Some(t) = child(node, "trajectory") {
            for (k, s) in children(t, "state").enumerate() {
                if k == MAX_STATES_PER_OBSTACLE {
                    return Err(self.err(
                        s,
                        Some(owner),
                        ErrorKind::TooMany {
                            what: "trajectory states",
                            count: children(t, "state").count(),
                            max: MAX_STATES_PER_OBSTACLE,
                        },
                    ));
                }
                trajectory.push(self.state(s, owner)?);
            }
        }
        Ok(Obstacle {
            id,
            line: self.line(node),
            obstacle_type,
            shape,
            initial_state,
            trajectory,
        })
    }

    fn planning_problem(&self, node: Node, known: &HashMap<i64, u32>) -> R<PlanningProblem> {
        let id = self.id_attr(node, "id", Some("planningProblem"))?;
        let owner = format!("planningProblem {id}");
        let initial_state = self.state(self.req(node, "initialState", &owner)?, &owner)?;
        let goal_states = children(node, "goalState")
            .map(|g| {
                let state = self.state(g, &owner)?;
                if let Some(Position::Lanelets(ids)) = &state.position
                    && let Some(p) = child(g, "position")
                {
                    for (l, &target) in children(p, "lanelet").zip(ids) {
                        if !known.contains_key(&target) {
                            return Err(self.err(
                                l,
                                Some(&owner),
                                ErrorKind::UnknownLanelet {
                                    field: "goalState.position.lanelet".into(),
                                    target,
                                },
                            ));
                        }
                    }
                }
                Ok(state)
            })
            .collect::<R<Vec<_>>>()?;
        Ok(PlanningProblem {
            id,
            line: self.line(node),
            initial_state,
            goal_states,
        })
    }
}
