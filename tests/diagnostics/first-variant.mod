# A wrist sub-assembly (paper Table 3) starts with an L unit; without `allow first-variant`
# rule 1 applies.
robot wrist {
    chain L1 - L4(pivot=-90deg) - L1(pivot=90deg)   # expect: error[first-variant] the first unit is L1; the paper's rule 1 fixes link 1 as H
}
