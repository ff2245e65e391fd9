robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    target plant at (0.35, 0, 0.20) m
    target pot at (0.30, 0.10, 0.20) m
    region plant box size (0.2, 0.1, 0) m at (0.35, 0, 0.15) m grid 3 x 2 x 1   # expect: error[duplicate-name] 'plant' is already defined in robot 'farm'
    task serve { visit plant, pot }
    path serve from plant to plant straight   # expect: error[duplicate-name] 'serve' is already defined in robot 'farm'
}
