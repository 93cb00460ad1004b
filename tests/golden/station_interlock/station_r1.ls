/PROG  STATION_R1
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "robomax_py";
PROG_SIZE	= 0;
CREATE		= DATE 00-01-01  TIME 00:00:00;
MODIFIED	= DATE 00-01-01  TIME 00:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 15;
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
   1:  !robomax_py ?, cell small_cell, ;
   2:  !+ cell file sha256 unknown, ;
   3:  !+ planned cycle 4.000 s ;
   4:  !robot kr125, tool spot_gun_c, ;
   5:  !+ axes joint_a1 joint_a2 ;
   6:  !+ joint_a3 joint_a4 joint_a5 ;
   7:  !+ joint_a6 ;
   8:  UFRAME_NUM=0 ;
   9:  UTOOL_NUM=0 ;
  10:J P[1] 100% FINE    ;
  11:  WAIT DI[2:r2_z1_clear]=ON    ;
  12:J P[2] 100% FINE    ;
  13:J P[3] 100% FINE    ;
  14:  DO[3:r1_z1_clear]=ON ;
  15:  DO[3:r1_z1_clear]=OFF ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 0,	
	J1=    0.0000 deg,	J2=  -90.0000 deg,	J3=   90.0000 deg,
	J4=    0.0000 deg,	J5=    0.0000 deg,	J6=    0.0000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 0,	
	J1=   30.0000 deg,	J2=  -80.0000 deg,	J3=   80.0000 deg,
	J4=    0.0000 deg,	J5=   20.0000 deg,	J6=    0.0000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 0,	
	J1=    0.0000 deg,	J2=  -90.0000 deg,	J3=   90.0000 deg,
	J4=    0.0000 deg,	J5=    0.0000 deg,	J6=    0.0000 deg
};
/END
