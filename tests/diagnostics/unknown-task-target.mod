robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    target plant at (0.35, 0, 0.20) m
    region tray box size (0.2, 0.1, 0) m at (0.35, 0, 0.15) m grid 3 x 2 x 1
    task serve { visit plant, pot, tray }   # expect: error[unknown-task-target] task 'serve' names 'pot', which is no target or region of the block
    path seam from plant to tray[3,0,0] straight   # expect: error[unknown-task-target] path 'seam' names 'tray[3,0,0]', outside the region's grid (indices from 0 to [2,1,0])
}
