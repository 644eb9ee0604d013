"""From a request to a plan: the motion-family records every reader of a type asks
(families.py), validation of a start or modify (validate.py), the planner
(planner.py) over the per-family profiles (profiles/), paths and streaming (paths.py), cams
(cams.py, cam_follow.py), and the plan the axes run (frames.py). Imports only base."""
