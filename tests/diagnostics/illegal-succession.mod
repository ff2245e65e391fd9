robot farm {
    chain H1 - L3 -
          H1 - L1   # expect: error[illegal-succession] H1 may not follow L3 (paper rules 2-3: H -> H, L; L -> L)
}
