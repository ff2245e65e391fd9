# Paper Table 3 / Fig. 6(c), configuration type II: H1-H4-L4 with an unconventional twist
# between skew joint axes 2 and 3, set at the H4 link module's connection port (rule 3).
robot skew {
    chain H1 - H4(pivot=-90deg, port=45deg) - L4
}
