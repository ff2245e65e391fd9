# Paper Table 3 / Fig. 6(a), configuration type I: a planar 2-DoF arm, H3-L4.
# DH (a1, 0, 0), (a2, pi, 0): both joint axes parallel; the link modules give a1 and a2.
robot planar {
    chain H3 - L4
}
