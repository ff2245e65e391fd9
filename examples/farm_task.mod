# The paper's vertical-farm arm (section 5.2, as in farm.mod) doing a task: take a seedling at
# the plant, set it down on every cell of a tray, come back; a shelf post stands in the way.
#     modc plan examples/farm_task.mod --task serve     plan and time the whole task
#     modc plan examples/farm_task.mod --task seam      tool0 along a straight segment
robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)

    tool at (0.06, 0, 0) m  # gripper tip beyond the last link module
    payload 50 g at (0.01, 0, 0) m  # a seedling in the gripper

    pose home (0, 0, 0) deg

    # A shelf post between the plant and the tray: the direct swing of joint 1 would hit it.
    box shelf size (0.08, 0.08, 0.40) m at (0.22, -0.22, 0.10) m

    target plant at (0.30, 0, 0.25) m
    target row_end at (0.30, 0.10, 0.25) m
    # The tray: 3 x 2 cells, 5 cm apart. The paper's 3-joint arm can point its gripper straight
    # down only folded back (joint 3 near 167 deg, on a ring 0.25 m out), so the cells are
    # served by position (each within 5 mm).
    region tray box size (0.10, 0.05, 0) m at (0, -0.30, 0.25) m grid 3 x 2 x 1 within 5 mm

    task serve { visit plant, tray, plant }
    path seam from plant to row_end straight
}
