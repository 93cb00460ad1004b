%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%

MODULE station_r1
  ! robomax_py ? | cell small_cell | cell file sha256 unknown | planned cycle 4.000 s
  ! robot kr125 | tool spot_gun_c | axes joint_a1 joint_a2 joint_a3 joint_a4 joint_a5 joint_a6
  ! RAPID module: mm, deg, quaternions [w, x, y, z], speeddata mm/s, zonedata mm
  CONST jointtarget jt1 := [[0.0000, -90.0000, 90.0000, 0.0000, 0.0000, 0.0000], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST jointtarget jt2 := [[30.0000, -80.0000, 80.0000, 0.0000, 20.0000, 0.0000], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST jointtarget jt3 := [[0.0000, -90.0000, 90.0000, 0.0000, 0.0000, 0.0000], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];

  PROC main()
    VelSet 100.0, 5000;
    AccSet 100.0, 100;
    MoveAbsJ jt1, vmax, fine, tool0;
    WaitDI r2_z1_clear, 1;
    MoveAbsJ jt2, vmax, fine, tool0;
    MoveAbsJ jt3, vmax, fine, tool0;
    SetDO doR1Z1, 1;
    SetDO doR1Z1, 0;
  ENDPROC

  PROC spot_weld(num n, num weld_time)
    ! default weld: rest for weld_time s; replace with the gun's technology package
    WaitTime \InPos, weld_time;
  ENDPROC
ENDMODULE
