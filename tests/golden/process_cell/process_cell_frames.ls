/PROG  PROCESS_CELL_FRAMES
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "robomax_py frames";
PROG_SIZE	= 0;
FILE_NAME	= PROCESS_CELL_FRAMES;
VERSION		= 0;
LINE_COUNT	= 21;
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
   3:  ! frames of PROCESS_CELL ;
   4:  PR[40]=LPOS ;
   5:  PR[40]=PR[40]-PR[40] ;
   6:  PR[40,1]=200.000 ;
   7:  PR[40,2]=0.000 ;
   8:  PR[40,3]=270.000 ;
   9:  PR[40,4]=-90.0000 ;
  10:  PR[40,5]=0.0000 ;
  11:  PR[40,6]=-90.0000 ;
  12:  UTOOL[2]=PR[40] ;
  13:  PR[41]=LPOS ;
  14:  PR[41]=PR[41]-PR[41] ;
  15:  PR[41,1]=1800.000 ;
  16:  PR[41,2]=0.000 ;
  17:  PR[41,3]=710.000 ;
  18:  PR[41,4]=0.0000 ;
  19:  PR[41,5]=0.0000 ;
  20:  PR[41,6]=0.0000 ;
  21:  UFRAME[3]=PR[41] ;
/POS
/END
