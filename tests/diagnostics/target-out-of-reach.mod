# A short arm (0.25 m from its first joint) and a target 2 m away: no joint angles reach it, and lint says so without planning.
robot small {
    chain H1 - L3(link=100mm)
    target shelf at (0.2, 0, 0.2) m
    target far at (2, 0, 0.2) m   # expect: warning[target-out-of-reach] target 'far' is out of reach: it is 2.001 m from joint_1, and tool0 is always within 0.247 m of it
}
