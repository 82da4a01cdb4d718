//! The recording's default layout (the blueprint), written as the rows the viewer reads, with
//! fixed ids.
//!
//! The 0.36 SDK's builders (`Spatial2DView::new`, `Horizontal::new`, …) give every view and
//! container a random UUID, which is part of the blueprint's entity paths and contents, so two
//! files would differ. This module writes the same archetypes as those builders (`ViewBlueprint`,
//! `ViewContents`, `ContainerBlueprint`, `ViewportBlueprint`, the panels) and the view properties
//! the builders cannot set (`VisualBounds2D`, `ScalarAxis`, `PlotLegend`) at the same paths, with
//! the ids 1, 2, 3, … in the order the views and containers are written.

use rerun::blueprint::components::{
    AutoLayout, AutoViews, ColumnShare, ContainerKind, Corner2D, IncludedContent, PanelState,
    QueryExpression, RootContainer, RowShare, ViewClass,
};
use rerun::components::Name;
use rerun::datatypes::{Bool, Float32, Range1D, Range2D};
use rerun::external::re_sdk_types::blueprint::archetypes::{
    ContainerBlueprint, PanelBlueprint, PlotLegend, ScalarAxis, TimePanelBlueprint, ViewBlueprint,
    ViewContents, ViewportBlueprint, VisualBounds2D,
};
use rerun::{AsComponents, EntityPath, SerializedComponentBatch};

use super::colors::entity_part;
use super::{RecorderParams, SIM_TIMELINE};

/// One row of the blueprint store.
pub(super) type BlueprintRow = (EntityPath, Vec<SerializedComponentBatch>);

/// A view: its class, title, origin, contents and properties (archetype name, value).
struct View {
    class: &'static str,
    name: String,
    origin: String,
    contents: Vec<String>,
    properties: Vec<(&'static str, Vec<SerializedComponentBatch>)>,
}

impl View {
    fn new(class: &'static str, name: impl Into<String>, origin: impl Into<String>) -> Self {
        Self {
            class,
            name: name.into(),
            origin: origin.into(),
            contents: vec!["$origin/**".into()],
            properties: Vec::new(),
        }
    }

    fn with_contents(mut self, contents: &[&str]) -> Self {
        self.contents = contents.iter().map(|c| (*c).to_owned()).collect();
        self
    }

    fn with_property(mut self, archetype: &'static str, value: &dyn AsComponents) -> Self {
        self.properties
            .push((archetype, value.as_serialized_batches()));
        self
    }
}

/// A node of the layout.
enum Node {
    View(View),
    Container {
        kind: ContainerKind,
        contents: Vec<Node>,
        column_shares: Option<Vec<f32>>,
        row_shares: Option<Vec<f32>>,
    },
}

fn vertical(contents: Vec<Node>, row_shares: Option<Vec<f32>>) -> Node {
    Node::Container {
        kind: ContainerKind::Vertical,
        contents,
        column_shares: None,
        row_shares,
    }
}

/// The fixed UUID number `n` (version 4 and RFC 4122 variant bits set, as the viewer expects).
fn fixed_uuid(n: u64) -> [u8; 16] {
    let mut bytes = [0_u8; 16];
    bytes[..4].copy_from_slice(b"msim");
    bytes[8..].copy_from_slice(&n.to_be_bytes());
    bytes[6] = 0x40 | (bytes[6] & 0x0f);
    bytes[8] = 0x80 | (bytes[8] & 0x3f);
    bytes
}

/// `bytes` written as a hyphenated UUID (how the SDK names `view/<id>` and `container/<id>`).
fn uuid_text(bytes: &[u8; 16]) -> String {
    let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
    format!(
        "{}-{}-{}-{}-{}",
        &hex[..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..]
    )
}

/// Writes `node` (children first, as the SDK does) into `rows`; returns its path and id.
fn write_node(
    node: &Node,
    next_id: &mut u64,
    rows: &mut Vec<BlueprintRow>,
) -> (EntityPath, [u8; 16]) {
    match node {
        Node::View(view) => {
            *next_id += 1;
            let id = fixed_uuid(*next_id);
            let path = EntityPath::from(format!("view/{}", uuid_text(&id)));
            let contents = ViewContents::new(
                view.contents
                    .iter()
                    .map(|q| QueryExpression(q.clone().into())),
            );
            rows.push((
                path.join(&EntityPath::from_single_string("ViewContents")),
                contents.as_serialized_batches(),
            ));
            let origin = EntityPath::from(view.origin.as_str());
            let arch = ViewBlueprint::new(ViewClass(view.class.into()))
                .with_display_name(Name(view.name.clone().into()))
                .with_space_origin(origin.to_string());
            rows.push((path.clone(), arch.as_serialized_batches()));
            for (archetype, batches) in &view.properties {
                rows.push((
                    path.join(&EntityPath::from_single_string(*archetype)),
                    batches.clone(),
                ));
            }
            (path, id)
        }
        Node::Container {
            kind,
            contents,
            column_shares,
            row_shares,
        } => {
            let children: Vec<EntityPath> = contents
                .iter()
                .map(|child| write_node(child, next_id, rows).0)
                .collect();
            *next_id += 1;
            let id = fixed_uuid(*next_id);
            let mut arch = ContainerBlueprint::new(*kind);
            if !children.is_empty() {
                arch = arch.with_contents(
                    children
                        .iter()
                        .map(|p| IncludedContent(p.to_string().into())),
                );
            }
            if let Some(shares) = column_shares {
                arch = arch.with_col_shares(shares.iter().map(|&s| ColumnShare(Float32(s))));
            }
            if let Some(shares) = row_shares {
                arch = arch.with_row_shares(shares.iter().map(|&s| RowShare(Float32(s))));
            }
            let path = EntityPath::from(format!("container/{}", uuid_text(&id)));
            rows.push((path.clone(), arch.as_serialized_batches()));
            (path, id)
        }
    }
}

fn bounds(x: [f64; 2], y: [f64; 2]) -> VisualBounds2D {
    VisualBounds2D::new(Range2D {
        x_range: Range1D(x),
        y_range: Range1D(y),
    })
}

/// The default layout: the follow view over the whole-road view, the field's colour bar and the
/// event log on the left; one time-series view per series on the right; the side panels
/// collapsed and the time panel as its compact bar on `sim_time`. Returns the rows of the
/// blueprint store (all at `blueprint` = 0).
pub(super) fn blueprint_rows(params: &RecorderParams) -> Vec<BlueprintRow> {
    let w = params.follow_window_m;
    // The follow frame has Y flipped (up on screen), so the window's y range is flipped too.
    let follow = View::new(
        "2D",
        format!("Follow {} (m)", params.follow),
        "/world/follow",
    )
    .with_contents(&["/world/**"])
    .with_property(
        "VisualBounds2D",
        &bounds([-w.behind_m, w.ahead_m], [-w.side_m, w.side_m]),
    );
    // The road's own frame is scaled to fit these bounds (`entities::overview_frame`).
    let half_height_m = super::entities::OVERVIEW_HALF_HEIGHT_M;
    let road = View::new("2D", "Whole road (m)", "/world/overview")
        .with_contents(&["/world/**", "- /world/paths/**"])
        .with_property(
            "VisualBounds2D",
            &bounds(
                [-10.0, super::entities::OVERVIEW_LENGTH_M + 10.0],
                [-half_height_m, half_height_m],
            ),
        );
    let legend = View::new("2D", "Field scale (potential U)", "/legend").with_property(
        "VisualBounds2D",
        &bounds(
            [-10.0, f64::from(super::entities::COLOR_BAR_STEPS) + 10.0],
            [-12.0, 24.0],
        ),
    );
    let events = View::new("TextLog", "Events", "/events");
    let left = vertical(
        vec![
            Node::View(follow),
            Node::View(road),
            Node::View(legend),
            Node::View(events),
        ],
        Some(vec![3.0, 1.5, 1.2, 1.5]),
    );
    let plots: Vec<Node> = params
        .blueprint_series
        .iter()
        .map(|plot| {
            let mut view = View::new(
                "TimeSeries",
                plot.title.clone(),
                format!("/plots/{}", entity_part(&plot.series)),
            );
            if let Some(range) = plot.y_range {
                view =
                    view.with_property("ScalarAxis", &ScalarAxis::new().with_range(Range1D(range)));
            }
            Node::View(view.with_property(
                "PlotLegend",
                &PlotLegend::new().with_corner(Corner2D::RightBottom),
            ))
        })
        .collect();
    let root = if plots.is_empty() {
        Node::Container {
            kind: ContainerKind::Horizontal,
            contents: vec![left],
            column_shares: None,
            row_shares: None,
        }
    } else {
        Node::Container {
            kind: ContainerKind::Horizontal,
            contents: vec![left, vertical(plots, None)],
            column_shares: Some(vec![3.0, 2.0]),
            row_shares: None,
        }
    };
    let mut rows = Vec::new();
    let mut next_id = 0;
    let (_, root_id) = write_node(&root, &mut next_id, &mut rows);
    let viewport = ViewportBlueprint::new()
        .with_root_container(RootContainer(rerun::datatypes::Uuid { bytes: root_id }))
        .with_auto_layout(AutoLayout(Bool(false)))
        .with_auto_views(AutoViews(Bool(false)));
    rows.push(("viewport".into(), viewport.as_serialized_batches()));
    let collapsed = PanelBlueprint::new().with_state(PanelState::Collapsed);
    rows.push(("blueprint_panel".into(), collapsed.as_serialized_batches()));
    rows.push(("selection_panel".into(), collapsed.as_serialized_batches()));
    let time_panel = TimePanelBlueprint::new()
        .with_state(PanelState::Collapsed)
        .with_timeline(rerun::blueprint::components::TimelineName(
            SIM_TIMELINE.into(),
        ));
    rows.push(("time_panel".into(), time_panel.as_serialized_batches()));
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_uuids_are_version_4_uuids() {
        let text = uuid_text(&fixed_uuid(3));
        assert_eq!(text, "6d73696d-0000-4000-8000-000000000003");
        assert_ne!(uuid_text(&fixed_uuid(1)), uuid_text(&fixed_uuid(2)));
    }
}
