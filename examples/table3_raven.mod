# Paper Table 3 / Fig. 6(e), configuration type III: a RAVEN-II-like H4-H3-L1 with
# intersecting, unconventional twists set by the pivots (rule 2).
# RAVEN-II's axes meet at 75° and 52° (Hannaford et al.); 52° is not a multiple of the twist
# slot's 15° resolution, so the nearest realisable 45° is used. The H3 link module is printed
# 80.76 mm long so that all three axes meet in one point, the remote centre of motion.
robot raven {
    chain H4 - H3(pivot=-75deg, link=80.76mm) - L1(pivot=-45deg)
}
