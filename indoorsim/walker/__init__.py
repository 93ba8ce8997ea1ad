"""The simulated pedestrian, and the phone's pose on it (DESIGN §5).

* :mod:`~indoorsim.walker.route` — waypoints, or a shortest path between two points;
* :mod:`~indoorsim.walker.path` — the walked path: smoothed corners, keeping off walls;
* :mod:`~indoorsim.walker.pacing` — the speed profile along the path: legs paced to their
  times, slowing at the route's points;
* :mod:`~indoorsim.walker.gait` — the walker's parameters, step events, and :func:`walk`,
  which ties the stages into a :class:`~indoorsim.walker.gait.BodyTrajectory`;
* :mod:`~indoorsim.walker.physics` — the body as a pymunk disc steered against the walls;
* :mod:`~indoorsim.walker.motion` — intra-step motion: bounce, sway, trunk yaw, heel strikes;
* :mod:`~indoorsim.walker.carry_modes` — the phone's pose in each built-in carrying mode
  (the pocket's in :mod:`~indoorsim.walker.pocketed`);
* :mod:`~indoorsim.walker.handling` — the hand moving the phone from one mode's place
  to the next's;
* :mod:`~indoorsim.walker.carry` — :func:`carry`, the phone through a schedule of modes.
"""
