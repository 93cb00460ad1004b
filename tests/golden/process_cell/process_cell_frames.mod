%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%

MODULE process_cell_frames
  ! robomax_py 0.1.0 | cell process_cell | cell file sha256 88859a5ee20f1866af51228139925b98ff8d83876345bd50c8fce2a9b032b924 | planned cycle 5.462 s
  ! robot kr125 | tool spot_gun_c | axes joint_a1 joint_a2 joint_a3 joint_a4 joint_a5 joint_a6
  ! the frames process_cell uses: load with it, or compare with the calibrated ones (mm, quaternions [w, x, y, z]; work objects in the robot base frame, which is the world)
  PERS wobjdata fixture_plate := [FALSE, TRUE, "", [[1800.000, 0.000, 710.000], [1.000000000, 0.000000000, 0.000000000, 0.000000000]], [[0, 0, 0], [1, 0, 0, 0]]];
ENDMODULE
