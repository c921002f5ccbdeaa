"""The default model's faculties beyond the paper, one module each: its config section, its
state (saved and loaded by itself) and its behaviour.

- :mod:`~hippo_agent.faculties.path_integration`: odometry into a belief of where the robot is,
  anchored by the place code, and a drive to the place cells from it.
- :mod:`~hippo_agent.faculties.map`: a grid of what the rangefinder has shown, and its planner.
- :mod:`~hippo_agent.faculties.localisation`: the belief checked against the map: evidence while
  lost, the beam model's fit of the scan, look-alike places, surprising bumps.
- :mod:`~hippo_agent.faculties.exploration`: the dry run's sweep, transits and rest, a run's search.
- :mod:`~hippo_agent.faculties.homing`: back to where the goal was found, and a search round it.
- :mod:`~hippo_agent.faculties.reflexes`: an escape after a bump, clearance from walls.
- :mod:`~hippo_agent.faculties.worlds`: several worlds, each with its own map and memories, and
  which one the robot is in, from a glimpse of its first steps.

A faculty reads the shared senses and writes its own state; what one faculty's event means for
another (a failed search: the estimate is wrong) is routed by :class:`~hippo_agent.HippocampalAgent`.
"""
