"""Hand-made valid plans for the 2x2 example, shared by the plan, checker and CLI tests.

Waypoints were worked out with the exact checker: R1 asks for O2 to be moved away, picks O1,
passes below the inner wall and up the gap to W1, drops and returns (7 steps); R2 alone picks
O2, drops it in W2 from below (facing north, heading 90) and needs two GoTos back home
(6 steps), 7 when it answers R1 with Res(O2).
"""

from cosmop.events import parse_event

R1_MISSION = [parse_event(e) for e in ["away(O2,R1,R2)", "pick(R1,O1)", "drop(R1,O1,W1)", "return(R1)"]]
R1_ACTIONS = [
    ("Req", "O2"),
    ("GoTo", (1750, -1000, 0)),  # the pick pose of O1: touches O1, would overlap O2 were it not away
    ("PickUp", "O1"),
    ("GoTo", (-1500, -200, 0)),  # below the gap between the left wall and the inner wall
    ("GoTo", (-1500, 2050, 0)),  # up through the gap
    ("DropOff", "O1"),  # O1 at (-1250, 2050), wholly inside W1
    ("GoTo", (-2000, -1000, 0)),  # home
]
R2_MISSION = [parse_event(e) for e in ["pick(R2,O2)", "drop(R2,O2,W2)", "return(R2)"]]
R2_ACTIONS = [
    ("GoTo", (1650, -1000, 0)),  # the pick pose of O2
    ("PickUp", "O2"),
    ("GoTo", (1250, 1800, 90)),  # right of the inner wall's end (1000, 0), facing north
    ("DropOff", "O2"),  # O2 at (1250, 2050), wholly inside W2
    ("GoTo", (1250, -2000, 0)),  # straight down
    ("GoTo", (-2000, -2000, 0)),  # home
]
R2_RES_MISSION = [parse_event(e) for e in ["pick(R2,O2)", "away(O2,R1,R2)", "drop(R2,O2,W2)", "return(R2)"]]
R2_RES_ACTIONS = [*R2_ACTIONS[:2], ("Res", "O2"), *R2_ACTIONS[2:]]
