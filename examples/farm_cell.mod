# The vertical-farm cell of farm.mod (paper section 5.2) as a design problem: which chain of
# Mark-2 modules serves the cell - takes a seedling at the plant, sets it down on every cell of
# the tray with the gripper pointing down, and comes back - without touching the walls or the
# shelf post, carrying the seedling, fastest?
#   modc design examples/farm_cell.mod -o farm_designs/
# The paper's answer is H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm); see the README,
# "Task-based design", for what modc finds.
design farm_cell {
    tool at (0.06, 0, 0) m  # gripper tip beyond the last link module
    payload 50 g at (0.01, 0, 0) m  # a seedling in the gripper

    # One farm cell in front of the arm, open towards it (base_link frame).
    box floor size (0.30, 0.50, 0.02) m at (0.37, 0, 0.11) m
    box roof size (0.30, 0.50, 0.02) m at (0.37, 0, 0.45) m
    box back size (0.02, 0.50, 0.36) m at (0.53, 0, 0.28) m
    box left size (0.30, 0.02, 0.36) m at (0.37, 0.26, 0.28) m
    box right size (0.30, 0.02, 0.36) m at (0.37, -0.26, 0.28) m
    cylinder pot radius 0.04 m length 0.06 m at (0.44, 0, 0.15) m
    # The tray stands on a table to the arm's right, 10 cm below the top of the base's pedestal;
    # a shelf post rises at the table's corner, between the tray and the cell.
    box table size (0.20, 0.14, 0.02) m at (0, -0.30, -0.10) m
    cylinder post radius 0.015 m length 0.40 m at (0.12, -0.22, 0.07) m

    target plant at (0.30, 0, 0.25) m
    # The tray: a row of 3 seedling cells 5 cm apart, served from above with the gripper (tool0's
    # x axis) pointing down within 5 deg; the turn about that axis is free. (A 3-joint arm points
    # its tool straight down only on a surface of revolution: a row across the arm's reach lies on
    # it, a second row 3 cm further out no longer does, so the tray is served row by row.)
    region tray box size (0.10, 0, 0) m at (0, -0.31, -0.05) m grid 3 x 1 x 1  # 5 cm apart
            pointing (0, 0, -1) within 5 mm, 5 deg

    task serve { visit plant, tray, plant }
    units 3
    modules H1, L3, L4
    rank cycle_time, modules, mass
    compare with chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)  # the paper's arm
}
