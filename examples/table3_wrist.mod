# Paper Table 3 / Fig. 6(d), configuration type I: a spherical-wrist-like L1-L4-L1.
# DH (0, -pi/2, 0), (0, pi/2, 0), (0, 0, 0): successive axes perpendicular.
# A wrist is a sub-assembly meant to sit on an arm, so it does not start with an H module as
# the paper's rule 1 asks of a whole arm; `allow` says that on purpose.
robot wrist {
    chain L1 - L4(pivot=-90deg, port=90deg) - L1
    allow first-variant
}
