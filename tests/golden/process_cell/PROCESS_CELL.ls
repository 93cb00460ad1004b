/PROG  PROCESS_CELL
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "robomax_py";
PROG_SIZE	= 0;
CREATE		= DATE 00-01-01  TIME 00:00:00;
MODIFIED	= DATE 00-01-01  TIME 00:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 28;
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
   1:  !robomax_py 0.1.0, ;
   2:  !+ cell process_cell, ;
   3:  !+ cell file sha256 ;
   4:  !+ 88859a5ee20f1866af51228139925b ;
   5:  !+98ff8d83876345bd50c8fce2a9b032b ;
   6:  !+924, planned cycle 5.462 s ;
   7:  !robot kr125, tool spot_gun_c, ;
   8:  !+ axes joint_a1 joint_a2 ;
   9:  !+ joint_a3 joint_a4 joint_a5 ;
  10:  !+ joint_a6 ;
  11:  UFRAME_NUM=3 ;
  12:  UTOOL_NUM=2 ;
  13:J P[1] 100% FINE    ;
  14:  WAIT DI[5:clamp1_closed]=ON    ;
  15:J P[2] 100% CNT100    ;
  16:J P[3] 100% CNT10    ;
  17:L P[4:s7] 500mm/sec FINE    ;
  18:  CALL SPOT_WELD(1,.500) ;
  19:  !flange/s7 gun 2 schedule 4 ;
  20:L P[5] 500mm/sec CNT10    ;
  21:J P[6] 100% CNT10    ;
  22:L P[7:s8] 500mm/sec FINE    ;
  23:  CALL SPOT_WELD(2,.800) ;
  24:  !flange/s8 gun 2 schedule 7 ;
  25:L P[8] 500mm/sec CNT10    ;
  26:J P[9] 100% CNT25    ;
  27:J P[10] 100% CNT25    ;
  28:J P[11] 100% FINE    ;
/POS
P[1]{
   GP1:
	UF : 3, UT : 2,	
	J1=    0.0000 deg,	J2=  -90.0000 deg,	J3=   90.0000 deg,
	J4=    0.0000 deg,	J5=    0.0000 deg,	J6=    0.0000 deg
};
P[2]{
   GP1:
	UF : 3, UT : 2,	
	J1=   14.6863 deg,	J2= -112.3308 deg,	J3=  130.6160 deg,
	J4=    9.5876 deg,	J5=   47.0343 deg,	J6= -154.0441 deg
};
P[3]{
   GP1:
	UF : 3, UT : 2,	
	J1=    6.3938 deg,	J2=  -97.7023 deg,	J3=  132.6311 deg,
	J4=   -5.1505 deg,	J5=   45.4012 deg,	J6= -162.9750 deg
};
P[4:"s7"]{
   GP1:
	UF : 3, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =  -453.280  mm,	Y =   -84.790  mm,	Z =   165.510  mm,
	W =   79.6313 deg,	P =   -1.2535 deg,	R =   97.4375 deg
};
P[5]{
   GP1:
	UF : 3, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =  -405.865  mm,	Y =   -78.793  mm,	Z =   174.252  mm,
	W =   79.6313 deg,	P =   -1.2535 deg,	R =   97.4375 deg
};
P[6]{
   GP1:
	UF : 3, UT : 2,	
	J1=    2.5533 deg,	J2=  -98.0214 deg,	J3=  132.5956 deg,
	J4=   -4.7901 deg,	J5=   45.6532 deg,	J6= -164.6553 deg
};
P[7:"s8"]{
   GP1:
	UF : 3, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =  -451.500  mm,	Y =     0.000  mm,	Z =   170.000  mm,
	W =   79.6309 deg,	P =   -1.2561 deg,	R =   99.8489 deg
};
P[8]{
   GP1:
	UF : 3, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =  -404.406  mm,	Y =     7.982  mm,	Z =   178.738  mm,
	W =   79.6309 deg,	P =   -1.2561 deg,	R =   99.8489 deg
};
P[9]{
   GP1:
	UF : 3, UT : 2,	
	J1=    6.6170 deg,	J2=  -98.6987 deg,	J3=  133.6861 deg,
	J4=   -5.2077 deg,	J5=   45.3595 deg,	J6= -162.7116 deg
};
P[10]{
   GP1:
	UF : 3, UT : 2,	
	J1=    6.1667 deg,	J2= -105.8901 deg,	J3=  123.5195 deg,
	J4=   -4.0842 deg,	J5=   62.6301 deg,	J6= -164.9403 deg
};
P[11]{
   GP1:
	UF : 3, UT : 2,	
	J1=    0.0000 deg,	J2=  -90.0000 deg,	J3=   90.0000 deg,
	J4=    0.0000 deg,	J5=    0.0000 deg,	J6=    0.0000 deg
};
/END
