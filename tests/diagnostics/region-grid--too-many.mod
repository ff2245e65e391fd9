design cell {
    region tray box size (0.2, 0.1, 0.1) m at (0.35, 0, 0.15) m grid 100 x 100 x 2   # expect: error[region-grid] region 'tray' has 20,000 points, more than 10,000
}
