# Seven units: the Mark-2 library assembles at most six (3 H + 3 L).
robot snake {
    chain H1 - H4 - H3 - L4 - L3 - L1 - L2   # expect: error[too-many-units] the chain has 7 units; the library allows at most 6
}
