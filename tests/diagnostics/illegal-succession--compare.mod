# A design block's reference arm is checked as a robot's chain is, at the units as written.
design cell {
    target plant at (0.35, 0, 0.20) m
    compare with chain H1 - L3 -
        H4(pivot=-90deg) - L3   # expect: error[illegal-succession] H4 may not follow L3 (paper rules 2-3: H -> H, L; L -> L)
}
