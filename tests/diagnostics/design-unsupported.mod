# `base within` in a design block: the language has it, the search does not place the base yet
design farm {
    target plant at (0.30, 0.10, 0.25) m
    units 2 to 3
    base within box size (0.2, 0.2, 0) m at (0, 0, 0) m step 50 mm   # expect: warning[design-unsupported] `base within` is parsed but not searched yet by modc design
}
