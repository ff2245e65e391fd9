# The longest segment of this arm (joint_2 to tool0, 0.40 m) outweighs the rest (0.147 m): tool0 can never
# come near joint_1, so a target beside it is out of reach too.
robot long {
    chain H1 - L3(link=400mm)
    target ok at (0.4, 0, 0.3) m
    target beside at (0, 0.05, 0.2) m   # expect: warning[target-out-of-reach] target 'beside' is out of reach: it is 0.073 m from joint_1, and tool0 is always at least 0.253 m from it
    target edge at (0, 0.05, 0.2) m within 0.2 m   # inside the tolerance: no warning
}
