# Paper section 5.1, Example B (DH from Moulianitis et al. 2016), published sequence
# H1-H4-H4-L2-L2-L2. DH rows (a, alpha, d):
#   (0, -pi/2, 0.148) (0.3, 2.36, 0) (0.3, 2.36, 0) (0, -pi/2, 0.148) (0, -pi/2, 0.148) (0, 0, 0.075)
# 2.36 rad ~ 135° skew twists at the two H4 ports; the -pi/2 twists with a = 0 at pivots.
robot example_b {
    chain H1 - H4(pivot=-90deg, port=135deg) - H4(port=135deg) - L2 - L2(pivot=-90deg) -
            L2(pivot=-90deg)
}
