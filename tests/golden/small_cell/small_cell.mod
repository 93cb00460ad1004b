%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%

MODULE small_cell
  ! robomax_py 0.1.0 | cell small_cell | cell file sha256 6bdd9e0710192b7603b20d63ba10c8d20d75769150c8bd427604ec09a0453a6e | planned cycle 5.089 s
  ! robot kr125 | tool spot_gun_c | axes joint_a1 joint_a2 joint_a3 joint_a4 joint_a5 joint_a6
  ! RAPID module: mm, deg, quaternions [w, x, y, z], speeddata mm/s, zonedata mm
  CONST jointtarget jt1 := [[0.0000, -90.0000, 90.0000, 0.0000, 0.0000, 0.0000], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_1 := [FALSE, 51.899617, 77.849425, 77.849425, 7.784943, 77.849425, 7.784943];
  CONST jointtarget jt2 := [[6.6170, -105.8301, 123.4674, -4.1696, 62.6530, -164.4578], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST jointtarget jt3 := [[6.6170, -98.6987, 133.6861, -5.2077, 45.3595, -162.7116], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST speeddata v_lin1 := [500.000, 500, 5000, 1000];
  CONST robtarget p4 := [[1346.720, -84.790, 875.510], [0.501470274, 0.428743215, 0.475615273, 0.581804891], [0, -1, -2, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_2 := [FALSE, 14.894929, 22.342394, 22.342394, 2.234239, 22.342394, 2.234239];
  CONST robtarget p5 := [[1394.135, -78.793, 884.252], [0.501470274, 0.428743215, 0.475615273, 0.581804891], [0, -1, -2, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_3 := [FALSE, 24.669550, 37.004325, 37.004325, 3.700432, 37.004325, 3.700432];
  CONST jointtarget jt6 := [[2.5533, -98.0214, 132.5956, -4.7901, 45.6532, -164.6553], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST robtarget p7 := [[1348.500, 0.000, 880.000], [0.489107198, 0.418651975, 0.484518125, 0.592238853], [0, -1, -2, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_4 := [FALSE, 14.874377, 22.311566, 22.311566, 2.231157, 22.311566, 2.231157];
  CONST robtarget p8 := [[1395.594, 7.982, 888.738], [0.489107198, 0.418651975, 0.484518125, 0.592238853], [0, -1, -2, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_5 := [FALSE, 58.282044, 87.423066, 87.423066, 8.742307, 87.423066, 8.742307];
  CONST jointtarget jt9 := [[6.6170, -98.6987, 133.6861, -5.2077, 45.3595, -162.7116], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_6 := [FALSE, 35.027371, 52.541057, 52.541057, 5.254106, 52.541057, 5.254106];
  CONST jointtarget jt10 := [[6.6170, -105.8301, 123.4674, -4.1696, 62.6530, -164.4578], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST jointtarget jt11 := [[0.0000, -90.0000, 90.0000, 0.0000, 0.0000, 0.0000], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];

  PROC main()
    ! start at home; 2 spots, planned cycle 5.089 s
    VelSet 100.0, 5000;
    AccSet 100.0, 100;
    MoveAbsJ jt1, vmax, fine, spot_gun_c_tcp;  ! home
    MoveAbsJ jt2, vmax, z_1, spot_gun_c_tcp;  ! home -> s7, t 0.000 s, detour point 1
    MoveAbsJ jt3, vmax, fine, spot_gun_c_tcp;
    ! flange/s7: arrive 1.610 s, leave 2.110 s, alpha -10.0 beta 10.0 gamma 0.0 deg
    MoveL p4, v_lin1, fine, spot_gun_c_tcp;  ! approach
    spot_weld 1, 0.500;  ! flange/s7 gun 1 schedule 1
    MoveL p5, v_lin1, z_2, spot_gun_c_tcp;  ! retract
    MoveAbsJ jt6, vmax, z_3, spot_gun_c_tcp;  ! s7 -> s8, t 2.317 s
    ! flange/s8: arrive 2.711 s, leave 3.211 s, alpha -10.0 beta 10.0 gamma 0.0 deg
    MoveL p7, v_lin1, fine, spot_gun_c_tcp;  ! approach
    spot_weld 2, 0.500;  ! flange/s8 gun 1 schedule 1
    MoveL p8, v_lin1, z_4, spot_gun_c_tcp;  ! retract
    MoveAbsJ jt9, vmax, z_5, spot_gun_c_tcp;  ! s8 -> home, t 3.426 s, detour point 1
    MoveAbsJ jt10, vmax, z_6, spot_gun_c_tcp;  ! detour point 2
    MoveAbsJ jt11, vmax, fine, spot_gun_c_tcp;
  ENDPROC

  PROC spot_weld(num n, num weld_time)
    ! default weld: rest for weld_time s; replace with the gun's technology package
    WaitTime \InPos, weld_time;
  ENDPROC
ENDMODULE
