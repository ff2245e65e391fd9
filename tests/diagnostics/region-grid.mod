robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    region tray box size (0.2, 0.1, 0) m at (0.35, 0, 0.15) m grid 3 x 0 x 1   # expect: error[region-grid] the grid of region 'tray' needs a whole number of points >= 1 along y, got 0
}
