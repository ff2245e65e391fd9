robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    region tray box size (0.2, 0.1, 0) m at (0.35, 0, 0.15) m grid 3 x 2 x 2   # expect: error[region-grid] region 'tray' has size 0 along z but 2 points there
}
