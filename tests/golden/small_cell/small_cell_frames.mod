%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%

MODULE small_cell_frames
  ! robomax_py 0.1.0 | cell small_cell | cell file sha256 6bdd9e0710192b7603b20d63ba10c8d20d75769150c8bd427604ec09a0453a6e | planned cycle 5.089 s
  ! robot kr125 | tool spot_gun_c | axes joint_a1 joint_a2 joint_a3 joint_a4 joint_a5 joint_a6
  ! the frames small_cell uses: load with it, or compare with the calibrated ones (mm, quaternions [w, x, y, z]; work objects in the robot base frame, which is the world)
  PERS tooldata spot_gun_c_tcp := [TRUE, [[200.000, 0.000, 270.000], [0.500000000, -0.500000000, 0.500000000, -0.500000000]], [1, [200.000, 0.000, 270.000], [1, 0, 0, 0], 0, 0, 0]];  ! load: 1 kg at the TCP, a placeholder: replace with the gun's (LoadIdentify)
ENDMODULE
