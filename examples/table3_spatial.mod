# Paper Table 3 / Fig. 6(b), configuration type I: spatial 3-DoF H1-H4-L4.
# DH (0, -pi/2, d1), (a1, 0, 0), (a2, 0, 0): joint 2 is perpendicular to joint 1 (pivot of the
# H4 unit, rule 2), joints 2 and 3 are parallel (no twist).
robot spatial {
    chain H1 - H4(pivot=-90deg) - L4
}
