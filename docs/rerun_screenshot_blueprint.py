"""Blueprint used for the README screenshot: the recording's own layout plus a camera that
looks along the merge section (the default camera frames the whole 750 m road)."""
import sys

import rerun.blueprint as rrb

series = ["sideslip_rad", "yaw_rad", "yaw_rate_radps", "speed_mps", "planned_speed_mps"]
eye = rrb.EyeControls3D(kind=rrb.Eye3DKind.Orbital, position=[176.0, -17.0, 13.0],
                        look_target=[214.0, 3.5, 0.0], eye_up=[0.0, 0.0, 1.0])
road = rrb.Spatial3DView(name="Road", origin="/world", eye_controls=eye,
                         contents=["$origin/**", "- /world/fields/obstacle"], background=[30, 30, 34])
left = rrb.Vertical(road, rrb.TextLogView(name="Events", origin="/events"), row_shares=[3, 1])
plots = rrb.Vertical(*[rrb.TimeSeriesView(name=s, origin=f"/plots/{s}") for s in series])
bp = rrb.Blueprint(rrb.Horizontal(left, plots, column_shares=[3, 2]),
                   rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
                   rrb.TimePanel(state="collapsed", timeline="sim_time", play_state="paused"),
                   auto_views=False, auto_layout=False)
bp.save("mergesim", sys.argv[1])
