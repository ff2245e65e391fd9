# SYNTAX TEST "source.mod" "tasks: regions, visits, straight paths, base placement"
design cell {
    region tray box size (0.2, 0.1, 0) m at (0.35, 0, 0.15) m grid 3 x 2 x 1 rpy (0, 90, 0) deg within 5 mm
#   ^^^^^^ keyword.control.region.mod
#          ^^^^ entity.name.function.region.mod
#               ^^^ keyword.control.box.mod
#                                                             ^^^^ keyword.other.grid.mod
#                                                                    ^ keyword.other.x.mod
    region cups box size (0.1, 0, 0) m at (0.3, 0, 0.1) m grid 2 x 1 x 1 pointing (0, 0, -1) within 5 mm, 5 deg
#                                                                        ^^^^^^^^ keyword.other.pointing.mod
    region slot box size (0.1, 0, 0) m at (0.3, 0, 0.1) m turned (0, 0, 30) deg grid 2 x 1 x 1
#                                                         ^^^^^^ keyword.other.turned.mod
    task serve { visit plant, tray, tray[1,0,0] }
#   ^^^^ keyword.control.task.mod
#        ^^^^^ entity.name.function.task.mod
#                ^^^^^ keyword.other.visit.mod
    path seam from plant to tray straight
#   ^^^^ keyword.control.path.mod
#             ^^^^ keyword.other.from.mod
#                                ^^^^^^^^ keyword.other.straight.mod
    base within box size (0.2, 0.2, 0) m at (0, 0, 0) m step 50 mm yaw 0 to 90 deg step 45 deg
#   ^^^^ keyword.control.base.mod
#        ^^^^^^ keyword.other.within.mod
#               ^^^ keyword.control.box.mod
#                                                                  ^^^ keyword.other.yaw.mod
    rank cycle_time, energy, coverage
#   ^^^^ keyword.control.rank.mod
}
