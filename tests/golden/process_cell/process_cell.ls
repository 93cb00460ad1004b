/PROG  PROCESS_CELL
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "robomax_py";
PROG_SIZE	= 0;
FILE_NAME	= PROCESS_CELL;
VERSION		= 0;
LINE_COUNT	= 20;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/MN
   1:  ! robomax_py 0.1.0 | cell process_cell | cell file sha256 88859a5ee20f1866af51228139925b98ff8d83876345bd50c8fce2a9b032b924 | planned cycle 5.463 s ;
   2:  ! robot kr125 | tool spot_gun_c | axes joint_a1 joint_a2 joint_a3 joint_a4 joint_a5 joint_a6 ;
   3:  UFRAME_NUM=3 ;
   4:  UTOOL_NUM=2 ;
   5:  J P[1] 100% FINE ;
   6:  WAIT DI[5:clamp1_closed]=ON ;
   7:  J P[2] 100% CNT100 ;
   8:  J P[3] 100% CNT10 ;
   9:  L P[4] 500mm/sec FINE ;
  10:  CALL SPOT_WELD(1,0.500) ;
  11:  ! flange/s7 gun 2 schedule 4 ;
  12:  L P[5] 500mm/sec CNT10 ;
  13:  J P[6] 100% CNT10 ;
  14:  L P[7] 500mm/sec FINE ;
  15:  CALL SPOT_WELD(2,0.800) ;
  16:  ! flange/s8 gun 2 schedule 7 ;
  17:  L P[8] 500mm/sec CNT10 ;
  18:  J P[9] 100% CNT25 ;
  19:  J P[10] 100% CNT25 ;
  20:  J P[11] 100% FINE ;
/POS
P[1]{
   GP1:
	UF : 3, UT : 2,
	J1= 0.0000 deg,	J2= -90.0000 deg,	J3= 90.0000 deg,
	J4= 0.0000 deg,	J5= 0.0000 deg,	J6= 0.0000 deg
};
P[2]{
   GP1:
	UF : 3, UT : 2,
	J1= 14.6863 deg,	J2= -112.3308 deg,	J3= 130.6160 deg,
	J4= 9.5876 deg,	J5= 47.0343 deg,	J6= -154.0441 deg
};
P[3]{
   GP1:
	UF : 3, UT : 2,
	J1= 6.3938 deg,	J2= -97.7023 deg,	J3= 132.6311 deg,
	J4= -5.1505 deg,	J5= 45.4012 deg,	J6= -162.9750 deg
};
P[4]{
   GP1:
	UF : 3, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X = -453.280  mm,	Y = -84.790  mm,	Z = 165.510  mm,
	W = 79.6313 deg,	P = -1.2535 deg,	R = 97.4375 deg
};
P[5]{
   GP1:
	UF : 3, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X = -405.865  mm,	Y = -78.793  mm,	Z = 174.252  mm,
	W = 79.6313 deg,	P = -1.2535 deg,	R = 97.4375 deg
};
P[6]{
   GP1:
	UF : 3, UT : 2,
	J1= 2.5533 deg,	J2= -98.0214 deg,	J3= 132.5956 deg,
	J4= -4.7901 deg,	J5= 45.6532 deg,	J6= -164.6553 deg
};
P[7]{
   GP1:
	UF : 3, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X = -451.500  mm,	Y = 0.000  mm,	Z = 170.000  mm,
	W = 79.6309 deg,	P = -1.2561 deg,	R = 99.8489 deg
};
P[8]{
   GP1:
	UF : 3, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X = -404.406  mm,	Y = 7.982  mm,	Z = 178.738  mm,
	W = 79.6309 deg,	P = -1.2561 deg,	R = 99.8489 deg
};
P[9]{
   GP1:
	UF : 3, UT : 2,
	J1= 6.6170 deg,	J2= -98.6987 deg,	J3= 133.6861 deg,
	J4= -5.2077 deg,	J5= 45.3595 deg,	J6= -162.7116 deg
};
P[10]{
   GP1:
	UF : 3, UT : 2,
	J1= 6.1667 deg,	J2= -105.8901 deg,	J3= 123.5195 deg,
	J4= -4.0842 deg,	J5= 62.6301 deg,	J6= -164.9403 deg
};
P[11]{
   GP1:
	UF : 3, UT : 2,
	J1= 0.0000 deg,	J2= -90.0000 deg,	J3= 90.0000 deg,
	J4= 0.0000 deg,	J5= 0.0000 deg,	J6= 0.0000 deg
};
/END
