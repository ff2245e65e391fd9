robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    base within box size (0.2, 0.2, 0) m at (0, 0, 0) m step 50 mm   # expect: error[base-within-robot] `base within` belongs in design blocks: robot 'farm' stands at one base pose
}
