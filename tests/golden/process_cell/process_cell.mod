%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%

MODULE process_cell
  ! robomax_py 0.1.0 | cell process_cell | cell file sha256 88859a5ee20f1866af51228139925b98ff8d83876345bd50c8fce2a9b032b924 | planned cycle 5.462 s
  ! robot kr125 | tool spot_gun_c | axes joint_a1 joint_a2 joint_a3 joint_a4 joint_a5 joint_a6
  ! RAPID module: mm, deg, quaternions [w, x, y, z], speeddata mm/s, zonedata mm
  CONST jointtarget jt1 := [[0.0000, -90.0000, 90.0000, 0.0000, 0.0000, 0.0000], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_1 := [FALSE, 60.738883, 91.108325, 91.108325, 9.110832, 91.108325, 9.110832];
  CONST jointtarget jt2 := [[14.6863, -112.3308, 130.6160, 9.5876, 47.0343, -154.0441], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_2 := [FALSE, 17.290282, 25.935423, 25.935423, 2.593542, 25.935423, 2.593542];
  CONST jointtarget jt3 := [[6.3938, -97.7023, 132.6311, -5.1505, 45.4012, -162.9750], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST speeddata v_lin1 := [500.000, 500, 5000, 1000];
  CONST robtarget p4 := [[-453.280, -84.790, 165.510], [0.501470274, 0.428743215, 0.475615273, 0.581804891], [0, -1, -2, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_3 := [FALSE, 14.894929, 22.342394, 22.342394, 2.234239, 22.342394, 2.234239];
  CONST robtarget p5 := [[-405.865, -78.793, 174.252], [0.501470274, 0.428743215, 0.475615273, 0.581804891], [0, -1, -2, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_4 := [FALSE, 24.669550, 37.004325, 37.004325, 3.700432, 37.004325, 3.700432];
  CONST jointtarget jt6 := [[2.5533, -98.0214, 132.5956, -4.7901, 45.6532, -164.6553], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST robtarget p7 := [[-451.500, 0.000, 170.000], [0.489107198, 0.418651975, 0.484518125, 0.592238853], [0, -1, -2, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_5 := [FALSE, 14.874377, 22.311566, 22.311566, 2.231157, 22.311566, 2.231157];
  CONST robtarget p8 := [[-404.406, 7.982, 178.738], [0.489107198, 0.418651975, 0.484518125, 0.592238853], [0, -1, -2, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_6 := [FALSE, 58.282044, 87.423066, 87.423066, 8.742307, 87.423066, 8.742307];
  CONST jointtarget jt9 := [[6.6170, -98.6987, 133.6861, -5.2077, 45.3595, -162.7116], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_7 := [FALSE, 34.977241, 52.465862, 52.465862, 5.246586, 52.465862, 5.246586];
  CONST jointtarget jt10 := [[6.1667, -105.8901, 123.5195, -4.0842, 62.6301, -164.9403], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST jointtarget jt11 := [[0.0000, -90.0000, 90.0000, 0.0000, 0.0000, 0.0000], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];

  PROC main()
    ! start at home; 2 spots, planned cycle 5.462 s
    VelSet 100.0, 5000;
    AccSet 100.0, 100;
    MoveAbsJ jt1, vmax, fine, gun2;  ! home
    ! wait for clamp input clamp1_closed
    WaitDI diClamp1Closed, 1;
    MoveAbsJ jt2, vmax, z_1, gun2;  ! home -> s7, t 0.000 s, detour point 1
    MoveAbsJ jt3, vmax, z_2, gun2;
    ! flange/s7: arrive 1.681 s, leave 2.181 s, alpha -10.0 beta 10.0 gamma 0.0 deg
    MoveL p4, v_lin1, fine, gun2 \WObj:=fixture_plate;  ! approach
    spot_weld 1, 0.500;  ! flange/s7 gun 2 schedule 4
    MoveL p5, v_lin1, z_3, gun2 \WObj:=fixture_plate;  ! retract
    MoveAbsJ jt6, vmax, z_4, gun2;  ! s7 -> s8, t 2.389 s
    ! flange/s8: arrive 2.782 s, leave 3.582 s, alpha -10.0 beta 10.0 gamma 0.0 deg
    MoveL p7, v_lin1, fine, gun2 \WObj:=fixture_plate;  ! approach
    spot_weld 2, 0.800;  ! flange/s8 gun 2 schedule 7
    MoveL p8, v_lin1, z_5, gun2 \WObj:=fixture_plate;  ! retract
    MoveAbsJ jt9, vmax, z_6, gun2;  ! s8 -> home, t 3.798 s, detour point 1
    MoveAbsJ jt10, vmax, z_7, gun2;  ! detour point 2
    MoveAbsJ jt11, vmax, fine, gun2;
  ENDPROC

  PROC spot_weld(num n, num weld_time)
    ! default weld: rest for weld_time s; replace with the gun's technology package
    WaitTime \InPos, weld_time;
  ENDPROC
ENDMODULE
