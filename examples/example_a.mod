# Paper section 5.1, Example A (DH from Singh et al. 2018), as its published sequence
# H1-H4-H4-L1-L4-L2. DH rows (a, alpha, d):
#   (0, -pi/2, 0.148) (0.3, 0.26, 0) (0.3, 0, 0) (0.3, 0.26, 0) (0.3, pi/2, 0) (0, 0, 0.075)
# alpha = -pi/2 with a = 0 -> pivot of unit 2; 0.26 rad ~ 15° at the ports (rule 3).
# Row 4 has a = 0.3 but is published as L1 (no link module), contradicting rule 1: its 15°
# twist is set with the next unit's pivot instead. `modc dh2mod` follows the rules instead.
robot example_a {
    chain H1 - H4(pivot=-90deg, port=15deg) - H4 - L1 - L4(pivot=15deg, port=90deg) - L2
}
