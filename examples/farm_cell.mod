# The vertical-farm cell of farm.mod (paper section 5.2) as a design problem: which chain of
# Mark-2 modules reaches the plant and the tray, inside the cell's walls, carrying a seedling?
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

    target plant at (0.35, 0, 0.20) m
    target tray at (0.30, -0.08, 0.22) m

    units 2 to 3
    rank modules, mass, margin
    compare with chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)  # the paper's arm
}
